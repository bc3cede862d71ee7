// A fleet of LOGI cars in one `hil mock` process, as a fleet manager's
// test bench runs it: 200 cars on free ports, the listing kept short, every
// car in the ports file, and logi-client holding a session with the last car.
// Every wait is bounded.

#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

std::string port_in(const std::string& line) {
  std::smatch m;
  if (std::regex_search(line, m, std::regex(R"(tcp://[^ :]+:(\d+))"))) return m[1];
  return {};
}

TEST(HilMockFleet, TwoHundredCarsStartAndTheLastOneServesASession) {
  const TempDir temp("hil-mock-fleet");
  const std::string ports_file = temp.file("ports.txt");
  HilProcess mock(
      {"mock", "logi", "--count", "200", "--port", "0", "--seed", "1", "--ports-file", ports_file});
  ASSERT_TRUE(mock.wait_for_line("car0 connect to tcp://", 60s)) << mock.output();
  ASSERT_TRUE(mock.wait_for_line("198 more cars on free ports", 60s)) << mock.output();
  const auto last = mock.wait_for_line("car199 connect to tcp://", 60s);
  ASSERT_TRUE(last) << mock.output();
  // The other 198 cars are not listed one by one.
  EXPECT_EQ(mock.output().find("car100 connect to"), std::string::npos) << mock.output();

  // The ports file names every car once, each on its own port, the last
  // one where the listing said.
  std::istringstream listing(read_file(ports_file));
  std::set<std::string> ports;
  std::string name;
  std::string address;
  std::string last_in_file;
  while (listing >> name >> address) {
    ports.insert(port_in(address));
    last_in_file = name + " " + address;
  }
  EXPECT_EQ(ports.size(), 200u);
  EXPECT_EQ(port_in(last_in_file), port_in(*last));
  EXPECT_EQ(last_in_file.rfind("car199 ", 0), 0u) << last_in_file;

  const auto client =
      run_to_exit(LOGI_CLIENT_BINARY,
                  {"--port", port_in(*last), "connect", "mode MAN", "speed 40", "disconnect"}, 30s);
  EXPECT_EQ(client.exit_code, 0) << client.output;
  EXPECT_TRUE(contains(client.output, "ok   speed 40")) << client.output;
  EXPECT_FALSE(contains(client.output, "FAIL")) << client.output;
  EXPECT_TRUE(mock.wait_for_line("car199/link1 client connected", 10s)) << mock.output();
  EXPECT_EQ(mock.interrupt(30s), 0) << mock.output();
  EXPECT_TRUE(contains(mock.output(), "stopping (1 client(s) served)")) << mock.output();
}

TEST(HilMockFleet, VerboseListsEveryCar) {
  HilProcess mock({"mock", "logi", "--count", "20", "--port", "0", "-v"});
  ASSERT_TRUE(mock.wait_for_line("car19 connect to tcp://", 30s)) << mock.output();
  for (int i = 0; i < 20; ++i)
    EXPECT_TRUE(contains(mock.output(), "car" + std::to_string(i) + " connect to tcp://"))
        << i << "\n"
        << mock.output();
  // Ctrl-C as soon as the cars are listed still stops them cleanly.
  EXPECT_EQ(mock.interrupt(30s), 0) << mock.output();
}

TEST(HilMockFleet, CountsItCannotServeAreRefusedWithTheReason) {
  const auto past_ports =
      run_to_exit(HIL_BINARY, {"mock", "logi", "--port", "65500", "--count", "100"});
  EXPECT_EQ(past_ports.exit_code, 2) << past_ports.output;
  EXPECT_TRUE(contains(past_ports.output, "runs past port 65535")) << past_ports.output;

  const auto serial = run_to_exit(HIL_BINARY, {"mock", "arduino", "--count", "65"});
  EXPECT_EQ(serial.exit_code, 2) << serial.output;
  EXPECT_TRUE(contains(serial.output, "serial cars is at most 64")) << serial.output;

  const auto too_many = run_to_exit(HIL_BINARY, {"mock", "logi", "--count", "10001"});
  EXPECT_NE(too_many.exit_code, 0) << too_many.output;
  EXPECT_FALSE(contains(too_many.output, "connect to tcp://")) << too_many.output;

  // A hard limit on open files too low for the fleet: said before any car
  // starts, with how many it needs.
  const std::string hil = HIL_BINARY;
  const auto no_files = run_to_exit(
      "/bin/sh", {"-c", "ulimit -n 100 && exec '" + hil + "' mock logi --port 0 --count 100"});
  EXPECT_EQ(no_files.exit_code, 1) << no_files.output;
  EXPECT_TRUE(contains(no_files.output, "100 cars need about 264 open files")) << no_files.output;
  EXPECT_TRUE(contains(no_files.output, "the hard limit is 100")) << no_files.output;
  EXPECT_FALSE(contains(no_files.output, "connect to tcp://")) << no_files.output;
}

}  // namespace
}  // namespace hil::test
