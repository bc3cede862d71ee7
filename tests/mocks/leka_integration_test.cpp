// The Leka robot's mock firmware behind a real pty under the real-time
// driver, with a client that opens the port as a serial program does. Waits
// are bounded and generous; nothing asserts how fast the robot was.

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/protocol_adapter.hpp"
#include "mocks/leka.hpp"
#include "mocks/server.hpp"
#include "protocol/leka/codec.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/serial_port.hpp"
#include "tests/mocks/serial_support.hpp"

namespace hil::mocks {
namespace {

namespace leka = protocol::leka;
namespace fs = std::filesystem;
using protocol::Bytes;

const std::string kInfoLine = "LEKA name=leka firmware=1.0.0 buffer=128 state=ok\r\n";

using test::TempDir;

/// The master's end of the port: open(2) on the symlink, raw mode, every
/// byte the robot sends collected.
class SerialClient {
 public:
  SerialClient(asio::io_context& io, const std::string& path)
      : port_(io, path, B115200,
              [this](protocol::ByteView b) { received_.append(protocol::to_string(b)); }) {}

  void write(const Bytes& bytes) { port_.write(bytes); }
  std::string text() const { return received_; }

 private:
  std::string received_;
  test::SerialPort port_;  // last: it may write to received_ until it is gone
};

/// The robot behind pty://<tmpdir>/leka0 at 115200 baud, in real time.
struct LekaOverPty : ::testing::Test {
  LekaOverPty() {
    firmware = std::make_unique<LekaFirmware>(world, vehicle);
    ServerOptions options;
    options.listen = link::PtyEndpoint{path, 115200, {}};
    options.name = "leka";
    server = std::make_unique<MockServer>(context, *firmware, options);
    server->start();
  }
  ~LekaOverPty() override {
    client.reset();
    server.reset();
  }

  /// Opens the port and waits until the robot's side has noticed.
  void open_port() {
    client = std::make_unique<SerialClient>(io, path);
    ASSERT_TRUE(link::test::run_until(io, [&] { return server->client_connected(); }))
        << "the pty listener never saw the port open";
  }

  TempDir dir{"hil-leka"};
  std::string path = (dir.path / "leka0").string();
  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  sim::World world{sim::WorldDef{}};
  sim::Vehicle& vehicle = world.add_vehicle(sim::leka_robot());
  std::unique_ptr<LekaFirmware> firmware;
  std::unique_ptr<MockServer> server;
  std::unique_ptr<SerialClient> client;
};

TEST_F(LekaOverPty, AMultiCommandFrameLightsTheLedsAndDrivesAndInfoIsAnswered) {
  EXPECT_EQ(server->address(), "pty://" + path + "?baud=115200");
  ASSERT_TRUE(fs::is_symlink(path));
  open_port();
  const sim::Pose start = vehicle.pose();

  client->write(leka::encode(
      leka::CommandGroup{{leka::EarAll{{255, 0, 0}}, leka::BeltRange{0, 9, {0, 255, 0}},
                          leka::MotorAll{leka::kSpinForward, 200}}}));
  const auto& state = firmware->state();
  ASSERT_TRUE(link::test::run_until(
      io,
      [&] {
        return state.ears[1] == leka::Rgb{255, 0, 0} && state.belt[9] == leka::Rgb{0, 255, 0};
      }))
      << "the frame never took effect: " << firmware->summary();
  EXPECT_EQ(state.belt[10], leka::Rgb{});
  EXPECT_EQ(state.left, (LekaMotor{leka::kSpinForward, 200}));
  EXPECT_EQ(state.right, (LekaMotor{leka::kSpinForward, 200}));
  // Heading east from the start pose: the robot drives along +x.
  ASSERT_TRUE(link::test::run_until(io, [&] { return vehicle.pose().x_m > start.x_m + 0.05; }))
      << "the robot did not drive; it is at x = " << vehicle.pose().x_m;
  EXPECT_NEAR(vehicle.pose().y_m, start.y_m, 0.01);

  client->write(leka::encode(leka::CommandGroup{{leka::Info{}}}));
  ASSERT_TRUE(link::test::run_until(io, [&] { return client->text().size() >= kInfoLine.size(); }))
      << "no info line, got '" << client->text() << "'";
  EXPECT_EQ(client->text(), kInfoLine);

  client->write(leka::encode(leka::CommandGroup{{leka::StopRobot{}}}));
  ASSERT_TRUE(link::test::run_until(io, [&] {
    return state.left == LekaMotor{} && state.ears[0] == leka::Rgb{} &&
           vehicle.differential()->left_speed_mps() == 0.0;
  })) << firmware->summary();
  EXPECT_EQ(firmware->stats().frames_in, 3u);
  EXPECT_EQ(firmware->stats().bad_frames, 0u);
}

TEST_F(LekaOverPty, BadFramesGetNoAnswerAndTheNextFrameIsServed) {
  open_port();
  Bytes bad = leka::encode(leka::CommandGroup{{leka::MotorAll{leka::kSpinForward, 255}}});
  bad.back() ^= 0x01;                         // wrong checksum
  client->write(protocol::to_bytes("junk"));  // under 7 bytes: one run whatever the timing
  client->write(bad);
  client->write(leka::encode(leka::CommandGroup{{leka::Info{}}}));
  ASSERT_TRUE(link::test::run_until(io, [&] { return client->text().size() >= kInfoLine.size(); }))
      << "no info line, got '" << client->text() << "'";
  EXPECT_EQ(client->text(), kInfoLine);
  EXPECT_EQ(firmware->state().counters.bad_checksum, 1u);
  EXPECT_EQ(firmware->state().counters.garbage, 1u);
  EXPECT_EQ(firmware->state().left, LekaMotor{});
  EXPECT_EQ(vehicle.differential()->left_pwm(), 0);
}

}  // namespace
}  // namespace hil::mocks
