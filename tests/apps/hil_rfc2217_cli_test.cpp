// --rfc2217 of hil mock and rfc2217:// of hil proxy, as a user runs them:
// the options' errors, the warning beyond loopback, and bytes through a
// proxy whose clients speak RFC 2217. (pySerial's own client drives `hil
// mock arduino --rfc2217` in tests/apps/rfc2217/pyserial_rfc2217_test.py.)

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/support/connection.hpp"

namespace hil::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using namespace std::string_literals;

/// The port of the first rfc2217://HOST:PORT in `line`, or -1.
int rfc2217_port_in(const std::string& line) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex(R"(rfc2217://[0-9.]+:(\d+))"))) return -1;
  return std::stoi(m[1]);
}

TEST(HilRfc2217, BadOptionsAreClearErrors) {
  for (const CliRun& run : {
           says("mock logi --rfc2217 4000", 2, {"--rfc2217 serves a serial car (arduino, leka)"}),
           says("mock arduino --rfc2217 4000 --pty /tmp/hil-rfc2217-x", 2,
                {"--rfc2217 and --pty each give the car's serial port; choose one"}),
           says("mock arduino --rfc2217 fast", 2, {"--rfc2217 takes [ADDR:]PORT", "got \"fast\""}),
           says("mock arduino --rfc2217 127.0.0.1:70000", 2, {"--rfc2217 takes [ADDR:]PORT"}),
           says("mock arduino --rfc2217 :4000", 2, {"--rfc2217 takes [ADDR:]PORT"}),
           says("mock leka --rfc2217 65535 --count 2", 2, {"runs past port 65535"}),
           says("proxy --listen rfc2217://127.0.0.1 --upstream tcp://127.0.0.1:9", 1,
                {"expected rfc2217://HOST:PORT"}),
           says("proxy --listen tcp://127.0.0.1:0 --upstream rfc2217://127.0.0.1:4000", 1,
                {"cannot connect to an RFC 2217 server"}),
       })
    expect_run(run);
}

TEST(HilRfc2217, HelpShowsTheExamples) {
  expect_run(says("mock --help", 0, {"--rfc2217", "hil mock arduino --rfc2217 4000"}));
  expect_run(
      says("proxy --help", 0, {"rfc2217://ADDR:PORT", "--listen 'rfc2217://127.0.0.1:4000"}));
}

TEST(HilRfc2217, CarsOnConsecutivePortsAndAWarningBeyondLoopback) {
  HilProcess mock({"mock", "leka", "--rfc2217", "0.0.0.0:0", "--count", "2", "--no-status"});
  const auto car0 = mock.wait_for_line("car0 connect an RFC 2217 client to rfc2217://0.0.0.0:");
  ASSERT_TRUE(car0) << mock.output();
  EXPECT_THAT(*car0, HasSubstr("(the line at 115200 baud)"));
  ASSERT_TRUE(mock.wait_for_line("car1 connect an RFC 2217 client to rfc2217://0.0.0.0:"))
      << mock.output();
  ASSERT_TRUE(mock.wait_for_line("Ctrl-C stops")) << mock.output();
  EXPECT_THAT(mock.output(), HasSubstr("warning: RFC 2217 server listening on 0.0.0.0, "
                                       "reachable from other machines"));
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilRfc2217, NoWarningOnLoopback) {
  HilProcess mock({"mock", "arduino", "--rfc2217", "0", "--no-status"});
  ASSERT_TRUE(mock.wait_for_line("Ctrl-C stops")) << mock.output();
  EXPECT_THAT(mock.output(), HasSubstr("car0 connect an RFC 2217 client to rfc2217://127.0.0.1:"));
  EXPECT_THAT(mock.output(), Not(HasSubstr("reachable from other machines")));
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilRfc2217, TheProxyServesRfc2217ClientsInFrontOfACar) {
  HilProcess car({"mock", "logi", "--port", "0", "--no-status"});
  int car_port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(car, car_port));
  HilProcess proxy({"proxy", "--protocol", "logi", "--listen", "rfc2217://127.0.0.1:0?baud=115200",
                    "--upstream", "tcp://127.0.0.1:" + std::to_string(car_port)});
  const auto line = proxy.wait_for_line("clients connect to rfc2217://127.0.0.1:");
  ASSERT_TRUE(line) << proxy.output();
  const int port = rfc2217_port_in(*line);
  ASSERT_GT(port, 0) << *line;
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.ok());
  // SET-BAUDRATE 115200, then a request as data.
  const std::string set_baud = "\xff\xfa\x2c\x01\x00\x01\xc2\x00\xff\xf0"s;
  ASSERT_TRUE(client.send(set_baud + "LOGI:MD:MAN:0C#"));
  EXPECT_TRUE(client.read_until("FB:MD:1")) << client.received;
  // The answer to SET-BAUDRATE: the command + 100 and the rate in use.
  EXPECT_THAT(client.received, HasSubstr("\xff\xfa\x2c\x65\x00\x01\xc2\x00\xff\xf0"s));
  // A second client is refused while the first is connected.
  Conn second = tcp_connect(port);
  ASSERT_TRUE(second.ok());
  EXPECT_TRUE(proxy.wait_for_line("refused: the port is in use by 127.0.0.1:")) << proxy.output();
  EXPECT_EQ(proxy.interrupt(), 0);
  EXPECT_EQ(car.interrupt(), 0);
}

}  // namespace
}  // namespace hil::test
