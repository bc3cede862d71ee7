// libFuzzer target for the RFC 2217 server codec (link/rfc2217.hpp), which
// reads whatever a network client sends. Beyond "no crash": the bytes fed
// in pieces (sizes from the input's plan) and fed whole give the same data
// for the device, the same answers to the client, the same events and the
// same line settings; and no data byte comes out that was not sent.

#include <algorithm>
#include <cstdio>

#include "link/rfc2217.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

using hil::link::Rfc2217Event;
using hil::link::Rfc2217Server;

struct Seen {
  hil::link::Bytes to_device;
  hil::link::Bytes to_client;
  std::vector<Rfc2217Event> events;
};

void drain(Rfc2217Server& server, Seen& seen) {
  const auto device = server.take_to_device();
  seen.to_device.insert(seen.to_device.end(), device.begin(), device.end());
  const auto client = server.take_to_client();
  seen.to_client.insert(seen.to_client.end(), client.begin(), client.end());
  for (auto& e : server.take_events())
    seen.events.push_back(std::move(e));
}

bool same_events(const std::vector<Rfc2217Event>& a, const std::vector<Rfc2217Event>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.kind == y.kind && x.value == y.value && x.text == y.text;
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  Rfc2217Server::Config config;
  config.line.baud = 9600;

  Rfc2217Server whole(config);
  Seen at_once;
  whole.open();
  drain(whole, at_once);
  whole.receive(hil::link::ByteView(stream.data(), stream.size()));
  drain(whole, at_once);

  Rfc2217Server pieces(config);
  Seen in_pieces;
  pieces.open();
  drain(pieces, in_pieces);
  std::size_t at = 0;
  for (std::size_t k = 0; at < stream.size(); ++k) {
    const std::size_t want = plan.empty() ? 1 : std::max<std::size_t>(1, plan[k % plan.size()]);
    const std::size_t n = std::min(want, stream.size() - at);
    pieces.receive(hil::link::ByteView(stream.data() + at, n));
    drain(pieces, in_pieces);
    at += n;
  }

  if (at_once.to_device != in_pieces.to_device) {
    for (const auto* seen : {&at_once, &in_pieces}) {
      for (const auto b : seen->to_device)
        std::fprintf(stderr, "%02x ", b);
      std::fprintf(stderr, "\n");
    }
  }
  hil::fuzz::check(at_once.to_device == in_pieces.to_device, "device data depends on the pieces");
  hil::fuzz::check(at_once.to_client == in_pieces.to_client, "answers depend on the pieces");
  hil::fuzz::check(same_events(at_once.events, in_pieces.events), "events depend on the pieces");
  hil::fuzz::check(whole.settings() == pieces.settings(), "settings depend on the pieces");
  // Data for the device is what the client sent, less Telnet commands: never more.
  hil::fuzz::check(at_once.to_device.size() <= stream.size(), "more device data than was sent");
  const auto line = whole.settings();
  hil::fuzz::check(line.baud <= hil::link::rfc2217::kMaxBaud, "a rate above the limit was taken");
  return 0;
}
