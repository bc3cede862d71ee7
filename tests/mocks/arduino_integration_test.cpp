// The Arduino robot's mock firmware (profile `readme`) behind a real pty at 9600 baud, under
// the real-time driver, with a client that opens the port the way a serial
// program does. Waits are bounded and generous; no upper bound on timing.

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
#include <vector>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "mocks/arduino.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/serial_port.hpp"
#include "tests/mocks/serial_support.hpp"

namespace hil::mocks {
namespace {

namespace arduino = protocol::arduino;
namespace fs = std::filesystem;
using std::chrono::milliseconds;

using test::TempDir;

/// A serial program's end of the port: open(2) on the symlink, raw mode at
/// 9600 baud, and the answers decoded as the PC side decodes them.
class SerialClient {
 public:
  SerialClient(asio::io_context& io, const std::string& path)
      : port_(io, path, B9600, [this](protocol::ByteView b) { on_bytes(b); }) {}

  void write(const std::string& text) { port_.write(protocol::to_bytes(text)); }

  /// Answers decoded so far, oldest first; anything that did not decode is a
  /// test failure.
  std::vector<arduino::Message>& answers() { return answers_; }
  std::size_t bytes_received() const { return bytes_; }

 private:
  void on_bytes(protocol::ByteView bytes) {
    bytes_ += bytes.size();
    items_.clear();
    decoder_.feed(bytes, items_);
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<arduino::Message>>(&item)) {
        answers_.push_back(f->message);
      } else {
        ADD_FAILURE() << "undecodable bytes from the robot: "
                      << std::get<protocol::DecodeError>(item).detail;
      }
    }
  }

  arduino::Decoder decoder_;  // the PC's 256-byte guard
  std::vector<arduino::Item> items_;
  std::vector<arduino::Message> answers_;
  std::size_t bytes_ = 0;
  test::SerialPort port_;  // last: it may call on_bytes until it is gone
};

/// The robot behind pty://<tmpdir>/arduino0, driven in real time, in the
/// README's dialect (profile `readme`), whose frames these tests spell out;
/// arduino_sketch_test.cpp drives the real sketch's dialect.
struct ArduinoOverPty : ::testing::Test {
  void start(const std::string& query = "?baud=9600") {
    uri = "pty://" + (dir.path / "arduino0").string() + query;
    world.emplace(sim::WorldDef{});
    sim::Vehicle& vehicle = world->add_vehicle(sim::arduino_robot());
    ArduinoConfig config;
    config.dialect = arduino::Dialect::readme;
    firmware = std::make_unique<ArduinoFirmware>(*world, vehicle, config);
    ServerOptions options;
    options.listen = link::parse_endpoint(uri);
    options.name = "arduino";
    server = std::make_unique<MockServer>(context, *firmware, options);
    server->start();
  }
  std::string port_path() const { return (dir.path / "arduino0").string(); }

  std::unique_ptr<SerialClient> open_port() {
    auto client = std::make_unique<SerialClient>(io, port_path());
    EXPECT_TRUE(link::test::run_until(io, [&] { return server->client_connected(); }))
        << "the robot never saw the port open";
    return client;
  }

  /// Sends `frame` and waits for the next answer.
  std::optional<arduino::Message> exchange(SerialClient& client, const std::string& frame) {
    const std::size_t before = client.answers().size();
    client.write(frame);
    if (!link::test::run_until(io, [&] { return client.answers().size() > before; })) {
      return std::nullopt;
    }
    EXPECT_EQ(client.answers().size(), before + 1) << "more than one answer to " << frame;
    return client.answers()[before];
  }

  /// The request with SEQ `seq` is answered ACK `info` with the same SEQ.
  void expect_ack(SerialClient& client, std::uint8_t seq, arduino::Body body,
                  const std::string& info) {
    const std::string frame = arduino::encode_text({seq, std::move(body)});
    const auto answer = exchange(client, frame);
    ASSERT_TRUE(answer.has_value()) << "no answer to " << frame;
    EXPECT_EQ(*answer, (arduino::Message{seq, arduino::Ack{info}})) << "answer to " << frame;
  }

  /// Like expect_ack, for the ACK text's first characters.
  std::string ack_text(SerialClient& client, std::uint8_t seq, arduino::Body body) {
    const std::string frame = arduino::encode_text({seq, std::move(body)});
    const auto answer = exchange(client, frame);
    if (!answer) {
      ADD_FAILURE() << "no answer to " << frame;
      return {};
    }
    EXPECT_EQ(answer->seq, seq);
    const auto* a = std::get_if<arduino::Ack>(&answer->body);
    if (a == nullptr) {
      ADD_FAILURE() << "not an ACK: " << arduino::describe(*answer);
      return {};
    }
    return a->info;
  }

  void expect_nack(SerialClient& client, const std::string& frame, std::uint8_t seq,
                   arduino::NackCode code) {
    const auto answer = exchange(client, frame);
    ASSERT_TRUE(answer.has_value()) << "no answer to " << frame;
    EXPECT_EQ(*answer, (arduino::Message{seq, arduino::Nack{code}})) << "answer to " << frame;
  }

  TempDir dir{"hil-arduino"};
  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  std::string uri;
  std::optional<sim::World> world;
  std::unique_ptr<ArduinoFirmware> firmware;
  std::unique_ptr<MockServer> server;
};

TEST_F(ArduinoOverPty, ASessionWithEveryCommandAndEveryNackKeepsTheSeqs) {
  start();
  EXPECT_EQ(server->address(), uri);
  auto client = open_port();

  expect_ack(*client, 0x01, arduino::Ping{}, "OK");
  expect_ack(*client, 0x02, arduino::Help{}, std::string(ArduinoFirmware::help_text(arduino::Dialect::readme)));
  EXPECT_EQ(ack_text(*client, 0x03, arduino::StatusRequest{}).rfind("IDLE PWM=140 ", 0), 0u);
  expect_ack(*client, 0x04, arduino::SetSpeed{160}, "160");

  // A move, polled with STATUS until it ends, as the PC must.
  expect_ack(*client, 0x05, arduino::Move{10}, "OK");
  EXPECT_EQ(ack_text(*client, 0x06, arduino::StatusRequest{}).rfind("MOVING M:10 PWM=160", 0), 0u);
  std::uint8_t seq = 0x07;
  ASSERT_TRUE(link::test::run_until(io, [&] {
    return ack_text(*client, seq++, arduino::StatusRequest{}).rfind("IDLE PWM=160 ", 0) == 0;
  })) << "the move never ended";

  expect_ack(*client, 0x40, arduino::Rotate{-30}, "OK");
  expect_ack(*client, 0x41, arduino::Stop{}, "OK");
  EXPECT_EQ(ack_text(*client, 0x42, arduino::StatusRequest{}).rfind("IDLE PWM=160 ", 0), 0u);
  const std::string sonar = ack_text(*client, 0x43, arduino::SonarRead{});
  EXPECT_FALSE(sonar.empty());
  EXPECT_EQ(sonar.find_first_not_of("0123456789"), std::string::npos) << sonar;
  const std::string ir = ack_text(*client, 0x44, arduino::IrRead{});
  EXPECT_EQ(ir.rfind("L=", 0), 0u) << ir;
  EXPECT_NE(ir.find(" R="), std::string::npos) << ir;

  expect_nack(*client, "^45|V|160*00$", 0x45, arduino::NackCode::bad_cs);
  expect_nack(*client, arduino::frame_body("46|PING|x"), 0x46, arduino::NackCode::bad_fmt);
  expect_nack(*client, "^G1|PING|*66$", 0x00, arduino::NackCode::bad_seq);
  expect_nack(*client, arduino::frame_body("47|JUMP|"), 0x47, arduino::NackCode::bad_cmd);
  expect_nack(*client, arduino::frame_body("48|V|999"), 0x48, arduino::NackCode::bad_v);

  // A 97-byte frame is dropped: the next answer is the PING's.
  client->write(arduino::frame_body("49|M|" + std::string(87, '1')));
  expect_ack(*client, 0x4A, arduino::Ping{}, "OK");
  EXPECT_EQ(ack_text(*client, 0x4B, arduino::StatusRequest{}).rfind("IDLE PWM=160 ", 0), 0u);

  EXPECT_EQ(firmware->stats().connections, 1u);
  EXPECT_EQ(firmware->stats().bad_frames, 6u);  // five answered, one dropped
}

TEST_F(ArduinoOverPty, OpeningThePortResetsTheBoardAndEarlyBytesAreLost) {
  start("?baud=9600&reset_ms=1000");
  {
    auto client = open_port();
    // Sent while the board boots: lost, so never answered.
    client->write(arduino::encode_text({0x01, arduino::Ping{}}));
    link::test::run_for(io, milliseconds(1500));
    expect_ack(*client, 0x02, arduino::SetSpeed{200}, "200");
    for (const auto& answer : client->answers())
      EXPECT_NE(answer.seq, 0x01);
    EXPECT_EQ(ack_text(*client, 0x03, arduino::StatusRequest{}).rfind("IDLE PWM=200 ", 0), 0u);
  }
  ASSERT_TRUE(link::test::run_until(io, [&] { return !server->client_connected(); }))
      << "the robot never saw the port close";
  const std::uint64_t boots = firmware->state().boots;

  auto client = open_port();
  link::test::run_for(io, milliseconds(1500));
  EXPECT_EQ(firmware->state().boots, boots + 1);
  EXPECT_EQ(ack_text(*client, 0x04, arduino::StatusRequest{}).rfind("IDLE PWM=140 ", 0), 0u);
  EXPECT_EQ(firmware->stats().connections, 2u);
}

}  // namespace
}  // namespace hil::mocks
