// libFuzzer target for the Leka mock firmware: arbitrary master bytes, cut
// into writes at fuzzer-chosen points and times, under the invariants in
// firmware_fuzz_support.hpp (counters that add up, the robot inside the
// arena, no wakeup loop). The robot answers only INFO, with one text line,
// so its output is checked as whole "LEKA ..." lines.

#include <string>

#include "mocks/leka.hpp"
#include "sim/presets.hpp"
#include "tests/fuzz/firmware_fuzz_support.hpp"

namespace {

/// Splits the robot's output into lines; anything but a whole line of the
/// INFO answer is an error item.
class InfoLines {
 public:
  void feed(hil::protocol::ByteView bytes,
            std::vector<hil::protocol::DecodeItem<std::string>>& out) {
    for (const std::uint8_t b : bytes) {
      line_.push_back(b);
      if (b != '\n') continue;
      const std::string text(line_.begin(), line_.end());
      if (text.rfind("LEKA name=", 0) == 0 && text.ends_with("\r\n")) {
        out.emplace_back(hil::protocol::Frame<std::string>{text, line_, {}});
      } else {
        out.emplace_back(hil::protocol::DecodeError{
            hil::protocol::ErrorKind::bad_format, line_, "not an INFO line: " + text, {}});
      }
      line_.clear();
    }
  }
  void finish(std::vector<hil::protocol::DecodeItem<std::string>>& out) {
    if (line_.empty()) return;
    out.emplace_back(hil::protocol::DecodeError{
        hil::protocol::ErrorKind::truncated, line_, "unfinished line", {}});
    line_.clear();
  }

 private:
  hil::protocol::Bytes line_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil;
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::leka_robot());
  mocks::LekaFirmware firmware(world, vehicle);
  fuzz::drive_firmware<std::string>(firmware, [] { return InfoLines(); }, {}, {data, size});
  return 0;
}
