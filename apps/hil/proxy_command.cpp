// hil proxy: the fault-injecting proxy between real clients and real cars
// (or mocks), in real time, until Ctrl-C: one route from --listen and
// --upstream, several from a routes file (--config), and a control API
// (--api) that adds, changes and removes routes, toxics and faults live.

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include <iostream>
#include <random>

#include "apps/common/version.hpp"
#include "apps/hil/cli_common.hpp"
#include "config/error.hpp"
#include "control/api_server.hpp"
#include "control/proxy_hub.hpp"
#include "control/routes_config.hpp"
#include "link/asio_executor.hpp"
#include "link/faults/profile_yaml.hpp"
#include "link/proxy.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps {
namespace {

struct ProxyArgs {
  std::string protocol = "raw";
  std::string listen;
  std::string upstream;
  std::string name = "proxy";
  std::string profile;
  std::string faults;
  std::string api;
  std::string config;
  std::string wire_log;
  std::string pcap;
  std::optional<std::uint64_t> seed;
  bool quiet = false;
};

/// --api's [ADDR:]PORT: "8474" is 127.0.0.1:8474, "0.0.0.0:0" any interface
/// on a free port, "[::1]:8474" IPv6. nullopt when it is not that.
std::optional<control::ApiServerOptions> parse_api_address(const std::string& text) {
  control::ApiServerOptions options;
  std::string port = text;
  const auto colon = text.rfind(':');
  if (colon != std::string::npos) {
    std::string host = text.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
      host = host.substr(1, host.size() - 2);
    if (host.empty()) return std::nullopt;
    options.host = host;
    port = text.substr(colon + 1);
  }
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  const unsigned long number = std::stoul(port);
  if (number > 65535) return std::nullopt;
  options.port = static_cast<std::uint16_t>(number);
  return options;
}

/// The host a route listens on: a URI's host, or HOST of HOST:PORT.
std::string listen_host(const std::string& listen) {
  try {
    const link::Endpoint endpoint = link::parse_endpoint(listen);
    if (const auto* tcp = std::get_if<link::TcpEndpoint>(&endpoint)) return tcp->host;
    if (const auto* served = std::get_if<link::Rfc2217Endpoint>(&endpoint)) return served->host;
    return "";
  } catch (const std::exception&) {
    const auto colon = listen.rfind(':');
    return colon == std::string::npos ? "" : listen.substr(0, colon);
  }
}

void warn_if_reachable(const std::string& what, const std::string& host) {
  if (host.empty() || control::is_loopback_host(host)) return;
  std::cerr << "warning: " << what << " on " << host << ", reachable from other machines\n";
}

/// The line each route prints when it is ready.
std::string route_line(const control::ProxyHub::Route& route, std::uint64_t seed) {
  const auto& spec = route.spec;
  const auto& protocol = route.proxy->options().protocol;
  const std::string profile = protocol && !protocol->profile().empty()
                                  ? " (profile " + std::string(protocol->profile()) + ")"
                                  : std::string();
  std::string line = "hil proxy: route " + spec.name + ": ";
  line += "clients connect to " + route.proxy->address() + ", car at " +
          link::to_uri(route.proxy->options().upstream) + ", protocol " + spec.protocol + profile +
          ", " + std::to_string(spec.faults.rules.size()) + " fault rule(s)";
  if (!spec.toxics.empty()) line += ", " + std::to_string(spec.toxics.size()) + " toxic(s)";
  if (!spec.enabled) line += ", disabled";
  return line + ", seed " + std::to_string(seed) + " (replay with --seed " + std::to_string(seed) +
         ")";
}

/// The routes to start with: the --listen/--upstream one, then the file's.
/// Prints what is wrong and returns the exit status when one cannot be read.
std::optional<int> collect_routes(const ProxyArgs& args, std::vector<control::RouteSpec>& routes) {
  if (!args.listen.empty()) {
    control::RouteSpec spec;
    spec.name = args.name;
    spec.listen = args.listen;
    spec.upstream = args.upstream;
    spec.protocol = args.protocol;
    spec.profile = args.profile;
    try {
      if (std::holds_alternative<link::Rfc2217Endpoint>(link::parse_endpoint(args.upstream))) {
        std::cerr << "hil proxy: --upstream " << args.upstream
                  << ": hil serves RFC 2217 (--listen rfc2217://...) but cannot connect to an "
                     "RFC 2217 server; give the car's serial port (pty:///dev/ttyUSB0) or "
                     "tcp://HOST:PORT\n";
        return 1;
      }
      (void)link::parse_endpoint(args.listen);
      if (!args.faults.empty()) spec.faults = link::load_fault_profile(args.faults);
    } catch (const std::exception& e) {
      std::cerr << "hil proxy: " << e.what() << '\n';
      return 1;
    }
    try {
      (void)link::protocol_adapter(args.protocol, args.profile);
    } catch (const protocol::ProfileError& e) {
      std::cerr << "hil proxy: --profile: " << e.what() << '\n';
      return 2;
    }
    routes.push_back(std::move(spec));
  }
  if (!args.config.empty()) {
    try {
      for (auto& spec : control::load_routes_file(args.config))
        routes.push_back(std::move(spec));
    } catch (const config::ConfigError& e) {
      std::cerr << "hil proxy: " << e.what() << '\n';
      return 1;
    } catch (const std::exception& e) {
      std::cerr << "hil proxy: --config " << args.config << ": " << e.what() << '\n';
      return 1;
    }
  }
  return std::nullopt;
}

/// The single route of --listen/--upstream alone, as hil proxy has always
/// run it: one link::Proxy, its wire log's links named "link<N>" and --pcap
/// the first link's file ("NAME-N.pcap" for link N).
int run_single_route(const ProxyArgs& args, control::RouteSpec spec, std::uint64_t seed) {
  link::ProxyOptions options;
  options.name = spec.name;
  options.listen = link::parse_endpoint(spec.listen);
  options.upstream = link::parse_endpoint(spec.upstream);
  options.faults = std::move(spec.faults);
  options.protocol = link::protocol_adapter(args.protocol, args.profile);
  options.seed = seed;
  options.wire_log_path = args.wire_log;
  options.pcap_path = args.pcap;
  if (!args.quiet) options.log = [](const std::string& line) { std::cout << line << std::endl; };

  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext context{executor, &io};
  // An rfc2217:// listener's refused connections and bad input are
  // printed even with -q: the client cannot see them.
  context.log = [](const std::string& line) { std::cout << line << std::endl; };
  link::Proxy proxy(context, options);
  // Caught before the start-up lines: a Ctrl-C right after them stops
  // cleanly instead of killing the process.
  asio::signal_set signals(io, SIGINT, SIGTERM);
  try {
    proxy.start();
  } catch (const std::exception& e) {
    std::cerr << "hil proxy: cannot listen on " << args.listen << ": " << e.what() << '\n';
    return 1;
  }
  warn_if_reachable("listening", listen_host(args.listen));
  std::cout << "hil proxy: clients connect to " << proxy.address() << ", car at "
            << link::to_uri(options.upstream) << ", protocol " << args.protocol
            << (options.protocol->profile().empty()
                    ? std::string()
                    : " (profile " + std::string(options.protocol->profile()) + ")")
            << ", " << options.faults.rules.size() << " fault rule(s), seed " << seed
            << " (replay with --seed " << seed << ")" << std::endl;
  signals.async_wait([&](const std::error_code& ec, int) {
    if (ec) return;
    std::cout << "hil proxy: stopping (" << proxy.links_opened() << " link(s) served, "
              << proxy.connections_refused() << " refused)" << std::endl;
    proxy.close();
    executor.call_after(std::chrono::milliseconds(100), [&io] { io.stop(); });
  });
  io.run();
  return 0;
}

int run_proxy(const ProxyArgs& args) {
  if (args.listen.empty() != args.upstream.empty()) {
    std::cerr << "hil proxy: " << (args.listen.empty() ? "--listen" : "--upstream")
              << " is required with " << (args.listen.empty() ? "--upstream" : "--listen")
              << " (one route: where clients connect, and the car)\n";
    return 2;
  }
  if (args.listen.empty() && args.api.empty() && args.config.empty()) {
    std::cerr << "hil proxy: nothing to proxy: give --listen and --upstream, --config "
                 "ROUTES.yaml, or --api [ADDR:]PORT to add routes later (hil proxy --help)\n";
    return 2;
  }
  std::optional<control::ApiServerOptions> api_options;
  if (!args.api.empty()) {
    api_options = parse_api_address(args.api);
    if (!api_options) {
      std::cerr << "hil proxy: --api " << args.api
                << ": expected [ADDR:]PORT, e.g. 8474, 0 (a free port) or 127.0.0.1:8474\n";
      return 2;
    }
    api_options->info.version = std::string(project_version());
  }
  std::vector<control::RouteSpec> routes;
  if (auto status = collect_routes(args, routes)) return *status;
  const std::uint64_t seed = args.seed ? *args.seed : std::random_device{}();
  if (!api_options && args.config.empty())
    return run_single_route(args, std::move(routes[0]), seed);

  control::ProxyHubOptions options;
  options.seed = seed;
  options.wire_log_path = args.wire_log;
  options.pcap_dir = args.pcap;
  if (!args.quiet) options.log = [](const std::string& line) { std::cout << line << std::endl; };

  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext context{executor, &io};
  // An rfc2217:// listener's refused connections and bad input are
  // printed even with -q: the client cannot see them.
  context.log = [](const std::string& line) { std::cout << line << std::endl; };
  control::ProxyHub hub(context, options);
  // Caught before the start-up lines: a Ctrl-C right after them stops
  // cleanly instead of killing the process.
  asio::signal_set signals(io, SIGINT, SIGTERM);
  for (auto& spec : routes) {
    const std::string name = spec.name;
    const std::string listen = spec.listen;
    try {
      const auto& route = hub.create(std::move(spec));
      warn_if_reachable("listening", listen_host(listen));
      std::cout << route_line(route, options.seed) << std::endl;
    } catch (const std::exception& e) {
      std::cerr << "hil proxy: route " << name << ": cannot listen on " << listen << ": "
                << e.what() << '\n';
      hub.close();
      return 1;
    }
  }
  std::unique_ptr<control::ApiServer> api;
  if (api_options) {
    warn_if_reachable("the control API (no login) listens", api_options->host);
    api = std::make_unique<control::ApiServer>(io, hub, *api_options);
    try {
      api->start();
    } catch (const std::exception& e) {
      std::cerr << "hil proxy: --api " << args.api << ": " << e.what() << '\n';
      hub.close();
      return 1;
    }
    std::cout << "hil proxy: control API at " << api->url() << std::endl;
  }
  signals.async_wait([&](const std::error_code& ec, int) {
    if (ec) return;
    std::size_t served = 0;
    std::size_t refused = 0;
    for (const auto* route : hub.routes()) {
      if (!route->proxy) continue;
      served += route->proxy->links_opened();
      refused += route->proxy->connections_refused();
    }
    std::cout << "hil proxy: stopping (" << served << " link(s) served, " << refused << " refused)"
              << std::endl;
    if (api) api->stop();
    hub.close();
    executor.call_after(std::chrono::milliseconds(100), [&io] { io.stop(); });
  });
  io.run();
  if (api) api->stop();
  return 0;
}

}  // namespace

void register_proxy(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<ProxyArgs>();
  auto* cmd = app.add_subcommand(
      "proxy", "Put the fault injector between clients and cars (real time), with a control API");
  cmd->add_option("--protocol", args->protocol,
                  "Frame-aware faults and decoded logs for: logi, wr8, arduino, leka, raw")
      ->check(CLI::IsMember({"logi", "wr8", "arduino", "leka", "raw"}));
  cmd->add_option("--profile", args->profile,
                  "The car's profile the frames are judged by (hil profiles CAR lists them; "
                  "default: the car's default), e.g. arduino --profile readme");
  cmd->add_option("--listen", args->listen,
                  "Where the client connects: tcp://127.0.0.1:PORT, pty:///PATH[?baud=9600], or "
                  "rfc2217://ADDR:PORT[?baud=9600] for an RFC 2217 client (a Windows COM port "
                  "redirector, pySerial; one client at a time)");
  cmd->add_option("--upstream", args->upstream,
                  "The car: tcp://HOST:PORT, or pty:///dev/ttyUSB0 for a serial device");
  cmd->add_option("--name", args->name,
                  "The --listen/--upstream route's name in the control API (default: proxy)");
  cmd->add_option("--faults", args->faults,
                  "Fault profile (YAML, see docs/faults.md); none: a clean pass-through");
  cmd->add_option("--config", args->config,
                  "Routes file (YAML, see docs/proxy-api.md): several routes, each with its "
                  "faults and toxics");
  cmd->add_option("--api", args->api,
                  "Serve the control API (Toxiproxy-compatible, see docs/proxy-api.md) on "
                  "[ADDR:]PORT; PORT alone is 127.0.0.1:PORT, 0 a free port. It has no login: "
                  "keep it on loopback");
  cmd->add_option("--seed", args->seed, "Seed for the fault rules (printed when chosen at random)");
  cmd->add_option("--log", args->wire_log,
                  "Write every byte of every link to this NDJSON wire log (links \"link<N>\"; "
                  "with --api or --config, \"ROUTE/link<N>\")");
  cmd->add_option("--pcap", args->pcap,
                  "Write the first link as a pcap (link N: NAME-N.pcap); with --api or --config, "
                  "a folder with one pcap per link (ROUTE-linkN.pcap)");
  cmd->add_flag("-q,--quiet", args->quiet,
                "Print only the start lines and errors, not each connection and fault");
  cmd->footer(
      "Examples:\n"
      "  hil proxy --protocol logi --listen tcp://127.0.0.1:9001 --upstream tcp://192.168.4.1:8080 "
      "\\\n"
      "            --faults scenarios/faults/sticky-packets.yaml --log wire.ndjson\n"
      "  hil proxy --config scenarios/proxy/routes-example.yaml --api 8474   (several routes, "
      "and\n"
      "            Toxiproxy clients change them live)\n"
      "  hil proxy --api 0   (no routes yet: POST /proxies adds them)\n"
      "  hil proxy --protocol arduino --listen 'pty:///tmp/hil-arduino0?baud=9600' --upstream "
      "pty:///dev/ttyUSB0\n"
      "  hil proxy --protocol arduino --listen 'rfc2217://127.0.0.1:4000?baud=9600' \\\n"
      "            --upstream pty:///dev/ttyACM0   (a real board, shared with RFC 2217 clients)\n"
      "  hil proxy --protocol wr8 --profile svgui-head --listen tcp://127.0.0.1:5557 \\\n"
      "            --upstream tcp://127.0.0.1:5556 --log wire.ndjson   (the real vehicle program; "
      "frames\n"
      "            are its length byte and packet)\n"
      "Stops cleanly on Ctrl-C (SIGINT) or SIGTERM.");
  cmd->callback([&run, args] { run = [args]() -> int { return run_proxy(*args); }; });
}

}  // namespace hil::apps
