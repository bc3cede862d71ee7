// libFuzzer target for the LOGI reference client's core (sans-I/O) under a
// hostile car: records of [operator action][pause][length][car bytes] on a
// virtual clock, every timer the core asks for run in between. Whatever the
// car sends, every frame the client writes must be a valid LOGI command, and
// the core must never ask to be woken at one instant over and over.

#include <algorithm>
#include <vector>

#include "client/logi/core.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

using namespace hil;
namespace proto = protocol::logi;

void check_actions(client::logi::LogiClientCore& core) {
  for (const auto& action : core.take_actions()) {
    const auto* send = std::get_if<client::logi::SendBytes>(&action);
    if (send == nullptr) continue;
    const protocol::ByteView bytes(reinterpret_cast<const std::uint8_t*>(send->text.data()),
                                   send->text.size());
    const auto item = proto::decode_frame(bytes);
    fuzz::check(std::holds_alternative<protocol::Frame<proto::Message>>(item),
                "the client wrote a frame that does not decode");
  }
  (void)core.take_events();
}

void operate(client::logi::LogiClientCore& core, link::Time now, std::uint8_t op) {
  const auto direction = proto::kAllDirections[(op >> 3) % proto::kAllDirections.size()];
  switch (op & 7) {
    case 0:
      (void)core.press(now, direction);
      break;
    case 1:
      (void)core.release(now);
      break;
    case 2:
      (void)core.emergency_stop(now);
      break;
    case 3:
      (void)core.submit(now, proto::SetSpeed{(op >> 3) * 100 / 31});  // 0..100
      break;
    case 4:
      (void)core.submit(now, proto::SetRun{(op & 8) != 0});
      break;
    case 5:
      core.on_closed(now);
      break;
    case 6:
      core.on_connected(now);
      break;
    default:
      break;  // only the car's bytes this time
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  client::logi::LogiClientCore core;
  link::Time now{};
  const link::Time end = now + link::seconds(30);
  core.connect(now);
  core.on_connected(now);
  check_actions(core);
  std::size_t pos = 0;
  while (pos + 3 <= size && now < end) {
    const std::uint8_t op = data[pos];
    const link::Time at = now + link::milliseconds(std::int64_t{data[pos + 1]} * 8);
    const std::size_t len = std::min<std::size_t>(data[pos + 2], size - pos - 3);
    const protocol::ByteView bytes(data + pos + 3, len);
    pos += 3 + len;
    fuzz::run_wakeups(
        now, at, [&] { return core.next_wakeup(); },
        [&] {
          core.on_timer(now);
          check_actions(core);
        },
        64, "the client keeps waking at one instant");
    operate(core, now, op);
    check_actions(core);
    core.on_bytes(now, bytes);
    check_actions(core);
  }
  return 0;
}
