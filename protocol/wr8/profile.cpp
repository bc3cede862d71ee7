#include "protocol/wr8/profile.hpp"

#include <algorithm>
#include <stdexcept>

namespace hil::protocol::wr8 {

std::vector<DataParameter> Profile::default_data_parameters() {
  return {
      DataParameter{0, "odometry", 4, ValueType::signed_int, "cm"},
      DataParameter{1, "speed", 4, ValueType::float32, "mps"},
      DataParameter{2, "wheel_angle", 4, ValueType::float32, "deg"},
      DataParameter{3, "battery", 1, ValueType::unsigned_int, "percent"},
  };
}

const DataParameter* Profile::data_parameter(std::uint8_t code) const {
  for (const auto& p : data_parameters) {
    if (p.code == code) return &p;
  }
  return nullptr;
}

const DataParameter* Profile::data_parameter(std::string_view name) const {
  for (const auto& p : data_parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

void Profile::validate() const {
  for (std::size_t i = 0; i < data_parameters.size(); ++i) {
    const auto& p = data_parameters[i];
    if (p.size_bytes != 1 && p.size_bytes != 2 && p.size_bytes != 4) {
      throw std::invalid_argument("WR8 profile: DATA parameter " + std::to_string(p.code) +
                                  " must be 1, 2 or 4 bytes");
    }
    if (p.type == ValueType::float32 && p.size_bytes != 4) {
      throw std::invalid_argument("WR8 profile: DATA parameter " + std::to_string(p.code) +
                                  " is a float but not 4 bytes");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (data_parameters[j].code == p.code) {
        throw std::invalid_argument("WR8 profile: DATA parameter code " + std::to_string(p.code) +
                                    " listed twice");
      }
    }
  }
}

const Profile& default_profile() {
  static const Profile profile;
  return profile;
}

std::string_view to_string(ByteOrder order) {
  return order == ByteOrder::little ? "little-endian" : "big-endian";
}

std::string_view to_string(BlockSizeUnit unit) {
  return unit == BlockSizeUnit::bytes ? "bytes" : "entries";
}

std::size_t longest_packet_bytes(const Profile& profile) {
  constexpr std::size_t kMaxSize = 255;
  if (profile.block_unit == BlockSizeUnit::bytes) return 7 + kMaxSize;  // DATA is the longest
  std::size_t widest = 0;
  for (const auto& p : profile.data_parameters)
    widest = std::max<std::size_t>(widest, p.size_bytes);
  // An unknown code ends a DATA packet early, so the widest known value
  // bounds every entry.
  return std::max({4 + kMaxSize * 4, 3 + kMaxSize * 5, 7 + kMaxSize * (1 + widest)});
}

}  // namespace hil::protocol::wr8
