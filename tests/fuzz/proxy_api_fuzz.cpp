// libFuzzer target for hil proxy's control API handlers
// (control/proxy_api.hpp), which read whatever an HTTP client sends. The
// input is one request: a method byte, then the path (with its query) up
// to a newline, the Content-Type up to the next, and the body. A hub with
// two routes over mem:// endpoints, one with a client talking through it,
// answers it in virtual time. Beyond "no crash": handle_api_request never
// throws, never answers 500 (a 500 is a bug in hil, not a bad request),
// its JSON replies parse, and the hub keeps running for a while after.

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "control/proxy_api.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"

namespace {

using namespace hil;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "control API contract broken: %s\n", what.c_str());
  std::abort();
}

std::string_view take_line(std::string_view& rest) {
  const auto newline = rest.find('\n');
  const std::string_view line = rest.substr(0, newline);
  rest = newline == std::string_view::npos ? std::string_view() : rest.substr(newline + 1);
  return line;
}

control::ApiRequest request_from(std::string_view input) {
  static constexpr const char* kMethods[] = {"GET",    "POST",    "PUT", "PATCH",
                                             "DELETE", "OPTIONS", "BREW"};
  control::ApiRequest request;
  request.method = kMethods[static_cast<unsigned char>(input[0]) % std::size(kMethods)];
  std::string_view rest = input.substr(1);
  const std::string_view target = take_line(rest);
  const auto question = target.find('?');
  request.path = std::string(target.substr(0, question));
  if (question != std::string_view::npos) {
    std::string_view query = target.substr(question + 1);
    while (!query.empty()) {
      const auto amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      const auto eq = pair.find('=');
      request.query.emplace_back(
          std::string(pair.substr(0, eq)),
          eq == std::string_view::npos ? "" : std::string(pair.substr(eq + 1)));
      query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    }
  }
  request.content_type = std::string(take_line(rest));
  request.body = std::string(rest);
  return request;
}

/// Two routes and a client whose link is open, as a running hil proxy has.
struct World {
  link::VirtualExecutor ex;
  link::TransportContext ctx{ex};
  std::unique_ptr<link::Listener> car;
  std::vector<link::BytePipePtr> car_pipes;
  link::BytePipePtr client;
  std::unique_ptr<control::ProxyHub> hub;

  World() {
    car = link::listen(ctx, link::parse_endpoint("mem://car"));
    car->start([this](link::BytePipePtr pipe) {
      car_pipes.push_back(pipe);
      std::weak_ptr<link::BytePipe> weak = pipe;
      pipe->start({[weak](link::ByteView bytes) {
                     if (auto self = weak.lock()) self->write(bytes);
                   },
                   [](std::error_code) {}});
    });
    hub = std::make_unique<control::ProxyHub>(ctx, control::ProxyHubOptions{});
    control::RouteSpec logi;
    logi.name = "car";
    logi.listen = "mem://front";
    logi.upstream = "mem://car";
    logi.protocol = "logi";
    hub->create(logi);
    control::RouteSpec raw;
    raw.name = "raw";
    raw.listen = "mem://raw";
    raw.upstream = "mem://car";
    hub->create(raw);
    link::connect(ctx, link::parse_endpoint("mem://front"),
                  [this](std::error_code ec, link::BytePipePtr pipe) {
                    if (ec) return;
                    client = pipe;
                    pipe->start({[](link::ByteView) {}, [](std::error_code) {}});
                    pipe->write(protocol::to_bytes("LOGI:SP:050:D7#"));
                  });
    ex.run_for(link::milliseconds(1));
  }
  ~World() {
    hub->close();
    ex.run_for(link::milliseconds(1));
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const control::ApiRequest request = request_from({reinterpret_cast<const char*>(data), size});
  World world;
  control::ApiReply reply;
  try {
    reply = control::handle_api_request(*world.hub, request);
  } catch (const std::exception& e) {
    fail(std::string("handle_api_request threw: ") + e.what());
  }
  if (reply.status < 200 || reply.status > 599) fail("status " + std::to_string(reply.status));
  if (reply.status == 500) fail("500: " + reply.body);
  if (reply.content_type == "application/json" && !nlohmann::json::accept(reply.body))
    fail("a JSON reply that does not parse: " + reply.body);
  // What the request changed keeps running: timers of toxics and rules
  // fire, the client writes again.
  if (world.client) world.client->write(protocol::to_bytes("LOGI:GS:8B#"));
  world.ex.run_for(link::seconds(2));
  return 0;
}
