#pragma once
// Seeded randomness for sensor noise and sensor faults. std::mt19937_64's
// output sequence is fixed by the C++ standard; the conversions to doubles
// and normal deviates are done here (the standard distributions differ
// between library implementations), so a seed replays on any toolchain.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace hil::sim {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// True with probability `p` (p <= 0 never, p >= 1 always, and neither
  /// extreme draws a number, so a disabled fault leaves the sequence alone).
  bool chance(double p) {
    if (p <= 0) return false;
    if (p >= 1) return true;
    return uniform() < p;
  }
  /// Normal deviate with mean 0 and the given standard deviation (Box-Muller).
  double normal(double stddev) {
    if (stddev <= 0) return 0;
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return stddev * std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
  }
  std::uint64_t next() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

/// Mixes a seed and a stream number into an independent seed (SplitMix64).
inline std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// FNV-1a over the bytes of values, for state hashes.
class StateHasher {
 public:
  template <class T>
  void add(const T& value) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      hash_ ^= bytes[i];
      hash_ *= 0x100000001B3ULL;
    }
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xCBF29CE484222325ULL;
};

}  // namespace hil::sim
