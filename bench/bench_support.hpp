#pragma once
// Decoder benchmarks: one stream of about 1 MiB per protocol, decoded fed
// whole and fed one byte at a time, reported as bytes/s and frames/s.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "protocol/common/decode.hpp"

namespace hil::bench {

inline constexpr std::size_t kStreamBytes = 1 << 20;

/// Repeats frames from `make_frame(i)` until the stream reaches kStreamBytes.
template <class MakeFrame>
std::vector<std::uint8_t> build_stream(MakeFrame make_frame, std::size_t* frame_count) {
  std::vector<std::uint8_t> stream;
  std::size_t i = 0;
  while (stream.size() < kStreamBytes) {
    const auto frame = make_frame(i++);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  *frame_count = i;
  return stream;
}

/// Decodes `stream` with pieces of `piece` bytes (0 = all at once) per
/// iteration and checks that every frame came out.
template <class Decoder, class Message>
void run_decoder(benchmark::State& state, const std::vector<std::uint8_t>& stream,
                 std::size_t frames, std::size_t piece) {
  std::vector<protocol::DecodeItem<Message>> items;
  items.reserve(frames + 16);
  for (auto _ : state) {
    Decoder decoder;
    items.clear();
    if (piece == 0) {
      decoder.feed(stream, items);
    } else {
      const std::span<const std::uint8_t> all(stream);
      for (std::size_t pos = 0; pos < all.size(); pos += piece) {
        decoder.feed(all.subspan(pos, std::min(piece, all.size() - pos)), items);
      }
    }
    decoder.finish(items);
    benchmark::DoNotOptimize(items.data());
    if (items.size() != frames) state.SkipWithError("decoder lost or split frames");
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
  state.counters["frames_per_s"] = benchmark::Counter(
      static_cast<double>(frames), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["stream_bytes"] = static_cast<double>(stream.size());
}

/// Registers "<name>/whole" and "<name>/bytewise" for a decoder over a stream.
template <class Decoder, class Message, class MakeFrame>
void register_decoder(const std::string& name, MakeFrame make_frame) {
  static std::size_t frames = 0;
  static const std::vector<std::uint8_t> stream = build_stream(make_frame, &frames);
  benchmark::RegisterBenchmark((name + "/whole").c_str(), [](benchmark::State& s) {
    run_decoder<Decoder, Message>(s, stream, frames, 0);
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark((name + "/bytewise").c_str(), [](benchmark::State& s) {
    run_decoder<Decoder, Message>(s, stream, frames, 1);
  })->Unit(benchmark::kMillisecond);
}

}  // namespace hil::bench
