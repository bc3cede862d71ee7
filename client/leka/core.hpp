#pragma once
// The Leka Alpha client library core, sans-I/O: a checked command-group
// builder, frames split at command boundaries, pacing that never overruns
// the robot's 128-byte serial buffer, and info requests with a timeout.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/common/connection.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/leka/message.hpp"

namespace hil::client::leka {

using link::Duration;
using link::Time;
using protocol::Bytes;
using protocol::ByteView;
namespace proto = protocol::leka;
using client::ConnectionState;
using client::to_string;

/// Why a builder call was refused; `field` names the wrong value.
/// not_in_profile: a command the client's profile does not have
/// (led.ear.range outside comspecs-v3).
enum class BuildError : std::uint8_t { ok, out_of_range, group_empty, not_in_profile };

struct BuildResult {
  BuildError error = BuildError::ok;
  std::string field;  ///< e.g. "led.belt.single led" when a value is wrong
  bool ok() const { return error == BuildError::ok; }
};

/// Collects commands fluently; a value out of range is not added, and the
/// first such problem is kept in result() (later calls still chain).
class GroupBuilder {
 public:
  explicit GroupBuilder(proto::ValueLimits limits = {}) : limits_(limits) {}

  GroupBuilder& info();
  GroupBuilder& stop_led();
  GroupBuilder& stop_motor();
  GroupBuilder& stop_robot();
  GroupBuilder& ear_all(proto::Rgb color);
  /// Ears first..last (0..1); a command of profile comspecs-v3 only.
  GroupBuilder& ear_range(int first, int last, proto::Rgb color);
  GroupBuilder& ear_single(int led, proto::Rgb color);
  GroupBuilder& belt_all(proto::Rgb color);
  GroupBuilder& belt_range(int first, int last, proto::Rgb color);
  GroupBuilder& belt_single(int led, proto::Rgb color);
  GroupBuilder& motor_all(int direction, int speed);
  GroupBuilder& motor_duo(int left_spin, int left_speed, int right_spin, int right_speed);
  GroupBuilder& motor_left(int spin, int speed);
  GroupBuilder& motor_right(int spin, int speed);
  GroupBuilder& motivator(int id);
  GroupBuilder& guidance(int id);

  /// ok, out_of_range (with the field) or group_empty.
  BuildResult result() const;
  const proto::CommandGroup& group() const { return group_; }

 private:
  bool check(std::string_view field, int value, int lo, int hi);
  GroupBuilder& add(proto::Command c);

  proto::ValueLimits limits_;
  proto::CommandGroup group_;
  BuildResult first_error_;
};

/// Splits a group into frames of at most `max_group_bytes` group bytes each,
/// cutting only between commands (a command is never split), in the ids and
/// checksum of `dialect`. Throws std::invalid_argument for a command the
/// dialect does not have.
std::vector<Bytes> split_frames(const proto::CommandGroup& group, std::size_t max_group_bytes,
                                proto::Dialect dialect = proto::Dialect::readme);

struct ClientConfig {
  /// Command ids and checksum of the robot: its profile (readme, the
  /// default, or comspecs_v3; docs/protocols/leka.md).
  proto::Dialect dialect = proto::Dialect::readme;
  /// Main-loop period of the robot: each pass empties its serial buffer.
  Duration loop_period = link::milliseconds(10);
  /// Most frame bytes sent within any loop_period (half-open window). Two
  /// windows can fall between two passes, so half the 128-byte buffer.
  std::size_t bytes_per_period = 64;
  /// Largest frame sent; never more than bytes_per_period.
  std::size_t max_frame_bytes = 64;
  /// How long an info request waits for the robot's line.
  Duration info_timeout = link::milliseconds(200);
  /// false sends every frame at once (to show what pacing prevents).
  bool paced = true;
};

/// The robot's info line, "LEKA name=.. firmware=.. buffer=.. state=..".
struct InfoReply {
  std::map<std::string, std::string> fields;
  std::string name;
  std::string firmware;
  std::optional<int> buffer_bytes;
  std::string state;
  friend bool operator==(const InfoReply&, const InfoReply&) = default;
};
/// nullopt unless the line holds "LEKA " and key=value fields after it;
/// whatever comes before the last "LEKA " is noise and is skipped.
std::optional<InfoReply> parse_info_line(std::string_view line);

using RequestId = std::uint64_t;
enum class InfoStatus : std::uint8_t { ok, timeout, closed };
struct InfoResult {
  InfoStatus status = InfoStatus::ok;
  std::optional<InfoReply> reply;
};

/// Bytes to write to the robot's serial port now.
struct SendFrame {
  Bytes bytes;
};
/// An info request ended (answered, timed out, or the port closed).
struct InfoDone {
  RequestId id = 0;
  InfoResult result;
};
/// A line from the robot (logged, and parsed when it is an info line).
struct LineReceived {
  std::string line;
};
/// A line that came with no info request waiting for it.
using Event = std::variant<InfoDone, LineReceived>;

class LekaClientCore {
 public:
  explicit LekaClientCore(ClientConfig config = {});

  /// The port is open: queued frames may go out.
  void on_connected(Time now);
  /// The port closed: queued frames are dropped, info requests end as closed.
  void on_closed(Time now);
  void on_bytes(Time now, ByteView bytes);
  void on_timer(Time now);

  /// Queues the group's frames (split as needed). Refuses a builder with an
  /// error; the frames go out paced.
  BuildResult send(Time now, const GroupBuilder& builder);
  BuildResult send(Time now, const proto::CommandGroup& group);
  /// Sends `info` and waits info_timeout for the line.
  RequestId info(Time now);

  std::optional<Time> next_wakeup() const;
  std::vector<SendFrame> take_actions();
  std::vector<Event> take_events();

  std::size_t queued_frames() const { return queue_.size(); }
  bool connected() const { return connected_; }
  /// The port in the shared vocabulary: connected (open) or disconnected.
  ConnectionState state() const {
    return connected_ ? ConnectionState::connected : ConnectionState::disconnected;
  }
  const ClientConfig& config() const { return config_; }

 private:
  struct Pending {
    RequestId id;
    std::optional<Time> deadline;  // set once the frame has gone out
  };
  struct Queued {
    Bytes bytes;
    std::optional<RequestId> info;
  };
  void pump(Time now);
  std::size_t window_bytes(Time now) const;
  void expire(Time now);

  ClientConfig config_;
  bool connected_ = false;
  std::deque<Queued> queue_;
  std::deque<std::pair<Time, std::size_t>> sent_;  // frames within the window
  std::deque<Pending> pending_;
  std::string line_;
  RequestId next_id_ = 1;
  std::vector<SendFrame> actions_;
  std::vector<Event> events_;
};

}  // namespace hil::client::leka
