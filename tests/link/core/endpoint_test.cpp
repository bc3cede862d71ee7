#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "link/endpoint.hpp"

namespace hil::link {
namespace {

using ::testing::HasSubstr;

TEST(Endpoint, ParsesTcp) {
  EXPECT_EQ(parse_endpoint("tcp://127.0.0.1:9000"), (Endpoint{TcpEndpoint{"127.0.0.1", 9000}}));
  EXPECT_EQ(parse_endpoint("tcp://[::1]:80"), (Endpoint{TcpEndpoint{"::1", 80}}));
  EXPECT_EQ(parse_endpoint("tcp://localhost:0"), (Endpoint{TcpEndpoint{"localhost", 0}}));
}

TEST(Endpoint, ParsesPtyWithOptions) {
  const auto e =
      std::get<PtyEndpoint>(parse_endpoint("pty:///tmp/hil-arduino0?baud=9600&reset_ms=200"));
  EXPECT_EQ(e.path, "/tmp/hil-arduino0");
  EXPECT_EQ(e.baud, 9600u);
  EXPECT_EQ(e.reset_on_open, milliseconds(200));
  EXPECT_EQ(std::get<PtyEndpoint>(parse_endpoint("pty:///dev/x")).baud, 0u);
}

TEST(Endpoint, ParsesMem) {
  EXPECT_EQ(parse_endpoint("mem://car0"), (Endpoint{MemEndpoint{"car0"}}));
  EXPECT_EQ(parse_endpoint("mem://car0?baud=9600"), (Endpoint{MemEndpoint{"car0", 9600}}));
}

TEST(Endpoint, ParsesRfc2217) {
  const auto e =
      std::get<Rfc2217Endpoint>(parse_endpoint("rfc2217://0.0.0.0:4000?baud=9600&reset_ms=250"));
  EXPECT_EQ(e.host, "0.0.0.0");
  EXPECT_EQ(e.port, 4000);
  EXPECT_EQ(e.baud, 9600u);
  EXPECT_EQ(e.reset_on_open, milliseconds(250));
  // Without an address: this machine only.
  EXPECT_EQ(parse_endpoint("rfc2217://:4001"),
            (Endpoint{Rfc2217Endpoint{"127.0.0.1", 4001, 0, Duration{0}}}));
  EXPECT_EQ(std::get<Rfc2217Endpoint>(parse_endpoint("rfc2217://[::1]:0")).host, "::1");
}

TEST(Endpoint, RoundTripsThroughText) {
  for (const char* uri :
       {"tcp://127.0.0.1:9000", "tcp://[::1]:80", "pty:///tmp/a?baud=9600&reset_ms=200",
        "pty:///tmp/b", "mem://x", "mem://x?baud=115200", "rfc2217://127.0.0.1:4000",
        "rfc2217://[::1]:4000?baud=115200", "rfc2217://10.0.0.2:0?baud=9600&reset_ms=200",
        "rfc2217://localhost:1?reset_ms=5"}) {
    EXPECT_EQ(to_uri(parse_endpoint(uri)), uri);
  }
}

TEST(Endpoint, ErrorsSayWhatWasExpected) {
  const auto message = [](const char* uri) {
    try {
      parse_endpoint(uri);
    } catch (const EndpointError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("127.0.0.1:9000"), HasSubstr("expected a URI such as tcp://"));
  EXPECT_THAT(message("tcp://127.0.0.1"), HasSubstr("tcp://HOST:PORT"));
  EXPECT_THAT(message("tcp://127.0.0.1:99999"), HasSubstr("port '99999' is not a number 0..65535"));
  EXPECT_THAT(message("tcp://:9000"), HasSubstr("host is empty"));
  EXPECT_THAT(message("pty://tmp/x"), HasSubstr("three slashes"));
  EXPECT_THAT(message("pty:///tmp/x?speed=9600"), HasSubstr("unknown option 'speed'"));
  EXPECT_THAT(message("pty:///tmp/x?baud=fast"), HasSubstr("baud 'fast'"));
  EXPECT_THAT(message("udp://1.2.3.4:5"), HasSubstr("unknown scheme 'udp'"));
  EXPECT_THAT(message("mem://"), HasSubstr("mem://NAME"));
  EXPECT_THAT(message("mem://car0?reset_ms=200"),
              HasSubstr("unknown option 'reset_ms' (known: baud)"));
  EXPECT_THAT(message("mem://car0?baud=5000000"), HasSubstr("baud '5000000' is not a number"));
  EXPECT_THAT(message("rfc2217://127.0.0.1"), HasSubstr("expected rfc2217://HOST:PORT"));
  EXPECT_THAT(message("rfc2217://127.0.0.1:70000"), HasSubstr("port '70000'"));
  EXPECT_THAT(message("rfc2217://127.0.0.1:4000?parity=even"),
              HasSubstr("unknown option 'parity' (known: baud, reset_ms)"));
  EXPECT_THAT(message("rfc2217://127.0.0.1:4000?baud=4000001"),
              HasSubstr("baud '4000001' is not a number 0..4000000"));
}

}  // namespace
}  // namespace hil::link
