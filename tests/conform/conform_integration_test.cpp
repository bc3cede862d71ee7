// hil's own mock plays the real car, in one profile, over a real TCP port
// or a real pty in real time: the probe records it, the capture reads back
// as recorded, and the check (in virtual time) finds the probed profile
// matching every exchange, ranks it first, and finds against each other
// profile exactly the differences the virtual-time tests pin
// (*_conform_test.cpp). Timing tolerances are widened here, and only
// here, because a loaded machine can hold a real-time answer back; the
// frames are compared exactly as always.
#include <gtest/gtest.h>

#include "conform/probe_runner.hpp"
#include "mocks/server.hpp"
#include "tests/conform/conform_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::conform {
namespace {

struct Case {
  mocks::CarKind car;
  const char* profile;
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string name = std::string(mocks::to_string(info.param.car)) + "_" + info.param.profile;
  for (auto& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

class ConformOverRealTransports : public ::testing::TestWithParam<Case> {};

TEST_P(ConformOverRealTransports, TheCheckFindsTheProfileTheCarPlays) {
  const auto [car, profile] = GetParam();
  hil::test::ScratchDir dir("hil-conform");
  auto driver = harness::make_run_driver(true);
  mocks::CarOptions options;
  options.kind = car;
  mocks::apply_profile(options.configs, car, profile);
  mocks::MockCar mock(std::move(options));
  link::Endpoint listen = mocks::default_endpoint(car, 0, profile);
  if (auto* tcp = std::get_if<link::TcpEndpoint>(&listen)) {
    tcp->host = "127.0.0.1";
    tcp->port = 0;
  } else if (auto* pty = std::get_if<link::PtyEndpoint>(&listen)) {
    pty->path = (dir.path() / "car").string();
  }
  mocks::ServerOptions server_options;
  server_options.listen = listen;
  mocks::MockServer server(driver->context(), mock.firmware(), std::move(server_options));
  server.start();

  const auto probe = make_probe(car, profile);
  const auto path = dir.path() / "capture.ndjson";
  const auto target = link::parse_endpoint(server.address());
  CaptureRecorder recorder(
      capture_header(probe, server.address(), 1),
      link::open_capture_log(path, link::protocol_adapter(mocks::to_string(car), profile)));
  const auto run = run_probe(*driver, target, probe, recorder);
  server.close();
  ASSERT_FALSE(run.error) << *run.error;
  ASSERT_EQ(run.capture.exchanges.size(), probe.exchanges.size());

  const auto read = link::read_capture(path);
  EXPECT_EQ(read, run.capture);

  Tolerances loose;
  loose.latency_abs = std::chrono::milliseconds(400);
  loose.period_abs = std::chrono::milliseconds(100);
  const auto result = check(read, loose);
  EXPECT_EQ(result.ranking().front(), profile);
  for (const auto& comparison : result.by_profile) {
    std::set<std::string> differ;
    std::string details;
    for (const auto& row : comparison.exchanges) {
      if (row.matches()) continue;
      differ.insert(row.name);
      for (const auto& d : row.differences)
        details += row.name + ": " + d + "\n";
    }
    EXPECT_EQ(differ, test::differing(car, profile, comparison.mock_profile))
        << "against profile " << comparison.mock_profile << ":\n"
        << details;
  }
}

INSTANTIATE_TEST_SUITE_P(OneProfilePerCar, ConformOverRealTransports,
                         ::testing::Values(Case{mocks::CarKind::logi, "firmware"},
                                           Case{mocks::CarKind::wr8, "svgui-head"},
                                           Case{mocks::CarKind::arduino, "readme"},
                                           Case{mocks::CarKind::leka, "comspecs-v3"}),
                         case_name);

}  // namespace
}  // namespace hil::conform
