#pragma once
// Shared by the firmware fuzz targets: a mock firmware driven the way the
// virtual-time driver drives it, with the fuzzer choosing how the client's
// bytes are cut into writes and how much time passes between them, and the
// invariants that must hold whatever a client sends.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <variant>
#include <vector>

#include "link/time.hpp"
#include "mocks/firmware.hpp"
#include "protocol/common/decode.hpp"
#include "sim/world.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace hil::fuzz {

/// Virtual time each input may cover at most: long enough for moves and
/// telemetry to run, short enough for thousands of inputs a second.
inline constexpr link::Duration kMaxRun = link::seconds(20);
/// Wakeups at one instant before the firmware counts as spinning.
inline constexpr int kMaxWakesAtOneInstant = 64;

/// One input: byte 0 holds flags for the target, then records of
/// [length byte][pause byte][length bytes]: the client writes the bytes
/// after the pause (milliseconds, x4). The last record may be short.
struct Record {
  link::Duration pause{};
  std::span<const std::uint8_t> bytes;
};
inline std::vector<Record> records_of(std::span<const std::uint8_t> data) {
  std::vector<Record> out;
  std::size_t pos = 0;
  while (pos + 2 <= data.size()) {
    const std::size_t len = std::min<std::size_t>(data[pos], data.size() - pos - 2);
    const auto pause = link::milliseconds(std::int64_t{data[pos + 1]} * 4);
    out.push_back({pause, data.subspan(pos + 2, len)});
    pos += 2 + len;
  }
  return out;
}

/// Drives `firmware` through `records` on a virtual clock, decoding
/// everything it sends with a fresh `Decoder` per connection (`make_decoder`)
/// and checking after every step:
///  - each byte the car sends decodes as a valid frame of its protocol;
///  - the stats count every byte in and out, and frames out match the
///    frames the client decoded;
///  - the car stays inside its arena;
///  - next_wakeup() moves on (no wakeup loop at one instant).
/// `prefix`, when not empty, is written first (a WR8 AUTH packet, so the
/// fuzzer explores the authenticated state too). A close the firmware asks
/// for is carried out and the client connects again at the next record.
template <class Message, class MakeDecoder>
void drive_firmware(mocks::Firmware& firmware, MakeDecoder make_decoder,
                    std::span<const std::uint8_t> prefix, std::span<const std::uint8_t> data) {
  auto decoder = make_decoder();
  std::vector<protocol::DecodeItem<Message>> items;
  std::uint64_t bytes_in = 0;
  std::uint64_t bytes_out = 0;
  std::uint64_t frames_decoded = 0;
  link::Time now{};
  const link::Time end = now + kMaxRun;

  const auto collect = [&] {
    const auto out = firmware.take_output();
    bytes_out += out.size();
    decoder.feed(out, items);
    for (const auto& item : items) {
      if (const auto* e = std::get_if<protocol::DecodeError>(&item)) {
        std::fprintf(stderr, "the car sent bytes its own protocol refuses: %s\n",
                     e->detail.c_str());
        std::abort();
      }
      ++frames_decoded;
    }
    items.clear();
    const auto pose = firmware.vehicle().pose();
    const auto& arena = firmware.world().arena();
    check(std::isfinite(pose.x_m) && std::isfinite(pose.y_m) && std::isfinite(pose.heading_rad),
          "the car's pose is not finite");
    if (arena.walls) {
      // The walls stand just outside [0, width] x [0, height]; the reference
      // point may not pass them.
      check(pose.x_m > -arena.wall_thickness_m &&
                pose.x_m < arena.width_m + arena.wall_thickness_m &&
                pose.y_m > -arena.wall_thickness_m &&
                pose.y_m < arena.height_m + arena.wall_thickness_m,
            "the car left the arena");
    }
    const auto& stats = firmware.stats();
    check(stats.bytes_in == bytes_in, "bytes_in differs from the bytes written");
    check(stats.bytes_out == bytes_out, "bytes_out differs from the bytes sent");
  };
  const auto close_if_asked = [&] {
    if (firmware.take_close() && firmware.connected()) {
      // The driver sends what was queued, then closes.
      collect();
      firmware.disconnect(now);
      decoder.finish(items);
      items.clear();  // a frame cut by the close is the client's problem
      decoder = make_decoder();
    }
  };
  // Runs every wakeup due up to `until`, as the driver's timer would.
  const auto run_until = [&](link::Time until) {
    run_wakeups(
        now, until, [&] { return firmware.next_wakeup(); },
        [&] {
          firmware.wake(now);
          collect();
          close_if_asked();
        },
        kMaxWakesAtOneInstant, "the firmware keeps waking at one instant");
  };

  firmware.connect(now);
  collect();
  if (!prefix.empty()) {
    bytes_in += prefix.size();
    firmware.receive(now, prefix);
    collect();
    close_if_asked();
  }
  for (const auto& record : records_of(data)) {
    const link::Time at = now + record.pause;
    if (at > end) break;
    run_until(at);
    if (!firmware.connected()) {
      firmware.connect(now);
      collect();
    }
    bytes_in += record.bytes.size();
    firmware.receive(now, record.bytes);
    collect();
    close_if_asked();
  }
  // Let whatever the input started (a move, a timeout) play out a little.
  run_until(now + link::seconds(2));
  collect();
  if (firmware.connected()) firmware.disconnect(now);
  check(firmware.stats().frames_out == frames_decoded, "frames_out differs from the frames sent");
}

}  // namespace hil::fuzz
