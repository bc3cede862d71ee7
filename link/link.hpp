#pragma once
// A link: a client-side pipe and a car-side pipe joined through one fault
// injector per direction, with observers (wire capture, timelines) watching
// every byte. Runs on any Executor, so the same link serves the virtual-time
// driver (mem pipes) and the real-time driver (TCP, pty).

#include <cstdint>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"
#include "link/faults/fault_injector.hpp"
#include "link/protocol_adapter.hpp"

namespace hil::link {

/// How a link ended.
struct LinkClose {
  enum class By : std::uint8_t {
    client,  ///< the client side closed or failed
    car,     ///< the car side closed or failed
    fault,   ///< a disconnect or reset rule broke the link
    hil,     ///< Link::close() was called
  };
  By by = By::hil;
  CloseMode mode = CloseMode::graceful;  ///< reset: the connection was aborted
  std::string reason;  ///< for a person: "car closed", "fault injected: reset (to_car)"
};
std::string_view to_string(LinkClose::By by);

/// Watches a link. Every callback runs on the link's executor.
class LinkObserver {
 public:
  virtual ~LinkObserver() = default;
  /// The link started joining these two pipes.
  virtual void on_open(Time /*at*/, const std::string& /*client*/, const std::string& /*car*/) {}
  /// Bytes one side wrote, before faults.
  virtual void on_sent(Time /*at*/, Direction /*d*/, protocol::ByteView /*bytes*/) {}
  /// Bytes handed to the receiving side, after faults.
  virtual void on_delivered(Time /*at*/, Direction /*d*/, protocol::ByteView /*bytes*/) {}
  virtual void on_fault(const FaultEvent& /*event*/) {}
  /// Direction d's sender ended its stream (TCP FIN) while still reading,
  /// and the end was passed on to the receiver after everything it sent:
  /// the other direction keeps flowing until it ends too.
  virtual void on_half_close(Time /*at*/, Direction /*d*/) {}
  /// The link closed: who closed it, how, and why.
  virtual void on_close(Time /*at*/, const LinkClose& /*close*/) {}
};

struct LinkOptions {
  std::shared_ptr<const ProtocolAdapter> protocol;  ///< null means raw
  FaultProfile to_car;                              ///< faults on bytes from the client to the car
  FaultProfile to_client;                           ///< faults on bytes from the car to the client
  std::uint64_t seed = 0;  ///< each direction derives its own stream from it
  std::vector<std::shared_ptr<LinkObserver>> observers;

  /// Gives each direction its rules of `profile` (for_direction()).
  void set_faults(const FaultProfile& profile) {
    to_car = for_direction(profile, Direction::to_car);
    to_client = for_direction(profile, Direction::to_client);
  }
};

struct LinkStats {
  std::uint64_t bytes_sent[2] = {0, 0};       ///< indexed by Direction
  std::uint64_t bytes_delivered[2] = {0, 0};  ///< indexed by Direction
  std::uint64_t faults = 0;
  std::uint64_t holds[2] = {0, 0};  ///< times the sender was held back (flow control)
};

/// Flow control between a link's two pipes: once the pipe a direction
/// writes to holds more than kLinkHighWaterBytes not yet taken by its peer,
/// the link stops reading the pipe that sends in that direction, and reads
/// it again when the backlog is down to kLinkLowWaterBytes. A fast sender
/// is then slowed to its receiver's pace, as on a direct connection,
/// instead of growing a queue until the send limit drops the receiver.
inline constexpr std::size_t kLinkHighWaterBytes = std::size_t{256} << 10;
inline constexpr std::size_t kLinkLowWaterBytes = std::size_t{64} << 10;

class Link : public std::enable_shared_from_this<Link> {
 public:
  static std::shared_ptr<Link> create(Executor& executor, BytePipePtr client, BytePipePtr car,
                                      LinkOptions options);
  ~Link();

  /// Starts carrying bytes; the observers see the link open now.
  void start();
  /// The same, the link opened at `opened_at` (the moment its connection
  /// was accepted): a car that starts its clock at the accept and the
  /// timeline's `open` then name one instant, however long setting up the
  /// link took on a loaded machine.
  void start(Time opened_at);
  /// Closes both sides.
  void close(CloseMode mode = CloseMode::graceful);
  bool is_open() const;

  /// Replaces one direction's fault rules while the link runs.
  void set_profile(Direction direction, FaultProfile profile);
  /// Replaces both directions' rules with theirs of `profile` (for_direction()).
  void set_faults(const FaultProfile& profile);
  LinkStats stats() const;

 private:
  Link(Executor& executor, BytePipePtr client, BytePipePtr car, LinkOptions options);
  struct Side;
  /// How a direction's sender ended: not yet, with a half-close (it may
  /// still read), or with a close.
  enum class Ended : std::uint8_t { no, half, closed };

  void on_bytes(Direction d, protocol::ByteView bytes);
  void on_side_ended(Direction d, Ended how);
  void on_side_closed(Direction from, std::error_code ec);
  void pass_end(Direction d);
  void pump(Direction d);
  void schedule(Direction d);
  void hold_back_if_full(Direction d);
  void shut(LinkClose close);

  Executor& executor_;
  BytePipePtr pipes_[2];  // [to_car] = car pipe (receives to_car bytes), [to_client] = client pipe
  std::unique_ptr<FaultInjector> injectors_[2];
  Executor::TimerId timers_[2] = {0, 0};
  Time timer_due_[2] = {Time{-1}, Time{-1}};
  Ended ended_[2] = {Ended::no, Ended::no};  // how that direction's sender ended
  bool passed_[2] = {false, false};          // its half-close reached the receiver (shutdown_send)
  Direction first_ended_ = Direction::to_car;  // whose sender ended first
  bool held_back_[2] = {false, false};         // that direction's sender is not being read
  std::vector<std::shared_ptr<LinkObserver>> observers_;
  LinkStats stats_;
  bool open_ = false;
  std::vector<InjectorOutput> scratch_;
};

}  // namespace hil::link
