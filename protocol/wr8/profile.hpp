#pragma once
// The byte-level choices the WR8 document leaves open, gathered in one
// struct so a firmware that differs can be described without code changes
// (docs/protocols/wr8.md explains each default).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hil::protocol::wr8 {

/// Order of the bytes of every multi-byte value (timestamp, parameter values).
enum class ByteOrder : std::uint8_t { little, big };

/// What the size byte of TASK, SETTINGS and DATA counts.
enum class BlockSizeUnit : std::uint8_t {
  bytes,    ///< bytes of the block that follows
  entries,  ///< parameters in the block
};

/// How a value's bits are shown to a person and read from the command line.
/// The codec itself never converts: it carries the exact bits.
enum class ValueType : std::uint8_t { signed_int, unsigned_int, float32 };

/// One row of the DATA parameter table.
struct DataParameter {
  std::uint8_t code = 0;
  std::string name;             ///< for describe() and the CLI, e.g. "speed"
  std::uint8_t size_bytes = 4;  ///< 1, 2 or 4 bytes on the wire
  ValueType type = ValueType::signed_int;
  std::string unit;  ///< suffix for describe(), e.g. "mps"
  friend bool operator==(const DataParameter&, const DataParameter&) = default;
};

inline constexpr std::size_t kTaskCount = 5;
inline constexpr std::size_t kSettingCount = 4;
inline constexpr std::size_t kAuthTextBytes = 10;

struct Profile {
  ByteOrder byte_order = ByteOrder::little;
  BlockSizeUnit block_unit = BlockSizeUnit::bytes;
  /// The string a GUI sends in AUTH. The codec carries any 10 bytes; this is
  /// what `hil encode wr8 auth` sends by default and what a mock expects.
  std::array<std::uint8_t, kAuthTextBytes> auth_text = {'H', 'I', 'L', '-', 'W',
                                                        'R', '8', '-', '0', '1'};
  /// Parameters each task code takes (check, drive, turn, blink, get-settings).
  std::array<std::uint8_t, kTaskCount> task_parameter_count = {0, 1, 1, 0, 0};
  /// How a task's parameters are presented: drive distance in cm and turn
  /// angle in degrees, both whole numbers by default.
  std::array<ValueType, kTaskCount> task_value_type = {ValueType::signed_int, ValueType::signed_int,
                                                       ValueType::signed_int, ValueType::signed_int,
                                                       ValueType::signed_int};
  /// How settings are presented: P, I, D as floats, servo zero as an integer.
  std::array<ValueType, kSettingCount> setting_value_type = {
      ValueType::float32, ValueType::float32, ValueType::float32, ValueType::signed_int};
  /// Known DATA parameters; a code not listed here cannot be sized.
  std::vector<DataParameter> data_parameters = default_data_parameters();

  /// Odometry int32 cm, speed float32 m/s, wheel angle float32 degrees,
  /// battery uint8 percent.
  static std::vector<DataParameter> default_data_parameters();

  /// The row for a DATA code, or nullptr when the profile does not know it.
  const DataParameter* data_parameter(std::uint8_t code) const;
  /// The row whose name is `name`, or nullptr.
  const DataParameter* data_parameter(std::string_view name) const;

  /// Throws std::invalid_argument for a profile no firmware could mean
  /// (duplicate DATA codes, sizes other than 1, 2 or 4, float not 4 bytes).
  void validate() const;

  friend bool operator==(const Profile&, const Profile&) = default;
};

/// The documented default profile (a shared instance).
const Profile& default_profile();

std::string_view to_string(ByteOrder order);
std::string_view to_string(BlockSizeUnit unit);

/// The longest packet this profile lets a header declare: 262 bytes when
/// sizes count bytes (a DATA header of 7 plus 255); more when they count
/// entries (TASK 4 + 255 * 4 = 1024, SETTINGS 3 + 255 * 5 = 1278, DATA
/// 7 + 255 * (1 + largest value)).
std::size_t longest_packet_bytes(const Profile& profile);

}  // namespace hil::protocol::wr8
