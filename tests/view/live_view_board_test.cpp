// `hil mock arduino --elf FILE --view 0` as a user runs it: the live view of
// hil's sketch on the emulated board, over real HTTP, while a client on the
// board's pty drives it: the pose follows the moves the sketch makes, and
// the page's wire holds the frames both ways.

#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "protocol/arduino/sketch.hpp"
#include "tests/mocks/serial_support.hpp"
#include "tests/view/view_test_support.hpp"

namespace hil::view::test {
namespace {

using namespace std::chrono_literals;

// What comes back within `limit`, read until a frame's end marker.
std::string answer(int fd, std::chrono::milliseconds limit) {
  std::string got;
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until && got.find('$') == std::string::npos) {
    char buffer[64];
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n > 0)
      got.append(buffer, static_cast<std::size_t>(n));
    else
      std::this_thread::sleep_for(5ms);
  }
  return got;
}

TEST(LiveViewBoard, ThePoseFollowsWhatTheSketchDoes) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "hil-view-board";
  std::filesystem::create_directories(dir);
  const std::string port = (dir / "robot").string();
  hil::test::HilProcess process({"mock", "arduino", "--elf", HIL_TEST_SKETCH_ELF, "--pty", port,
                                 "--view", "0", "--no-status"});
  const auto view = process.wait_for_line("view: http://127.0.0.1:");
  ASSERT_TRUE(view) << process.output();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(*view, m, std::regex(R"(http://127\.0\.0\.1:(\d+)/)")));
  httplib::Client c("127.0.0.1", std::stoi(m[1]));
  c.set_read_timeout(10, 0);
  const auto state = [&c]() -> json {
    const auto res = c.Get("/api/state");
    return res && res->status == 200 ? json::parse(res->body)["cars"][0] : json();
  };
  const json before = state();
  ASSERT_FALSE(before.is_null());

  const int fd = mocks::test::open_serial_port(port, B9600);
  std::this_thread::sleep_for(300ms);  // the board's reset and setup()
  const std::string move = protocol::arduino::sketch_frame("01", "M", "50");
  ASSERT_EQ(::write(fd, move.data(), move.size()), static_cast<ssize_t>(move.size()));
  EXPECT_EQ(answer(fd, 2000ms), protocol::arduino::sketch_frame("01", "ACK", "ACCEPTED"));
  std::this_thread::sleep_for(1500ms);  // 50 cm at 18 ms/cm: 900 ms, then at rest
  const json after = state();
  ::close(fd);

  // 50 cm forward, give or take the wheels' ramp and the sketch's own time.
  EXPECT_NEAR(distance_between(after["pose"], before["pose"]), 0.5, 0.05)
      << before["pose"] << after["pose"];
  bool saw_move = false;
  for (const auto& f : after["frames"]["to_car"])
    saw_move = saw_move || f["kind"] == "M";
  bool saw_answer = false;
  for (const auto& f : after["frames"]["to_client"])
    saw_answer = saw_answer || f["kind"] == "ACK";
  EXPECT_TRUE(saw_move) << after["frames"];
  EXPECT_TRUE(saw_answer) << after["frames"];
  process.interrupt();
}

}  // namespace
}  // namespace hil::view::test
