// hil proxy: the fault-injecting proxy between a real client and a real car
// (or a mock), in real time, until Ctrl-C.

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include <iostream>
#include <random>

#include "apps/hil/cli_common.hpp"
#include "link/asio_executor.hpp"
#include "link/faults/profile_yaml.hpp"
#include "link/proxy.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps {

void register_proxy(CLI::App& app, std::function<int()>& run) {
  struct Args {
    std::string protocol = "raw";
    std::string listen;
    std::string upstream;
    std::string profile;
    std::string faults;
    std::string wire_log;
    std::string pcap;
    std::optional<std::uint64_t> seed;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  auto* cmd =
      app.add_subcommand("proxy", "Put the fault injector between a client and a car (real time)");
  cmd->add_option("--protocol", args->protocol,
                  "Frame-aware faults and decoded logs for: logi, wr8, arduino, leka, raw")
      ->check(CLI::IsMember({"logi", "wr8", "arduino", "leka", "raw"}));
  cmd->add_option("--profile", args->profile,
                  "The car's profile the frames are judged by (hil profiles CAR lists them; "
                  "default: the car's default), e.g. arduino --profile readme");
  cmd->add_option("--listen", args->listen,
                  "Where the client connects: tcp://127.0.0.1:PORT, pty:///PATH[?baud=9600], or "
                  "rfc2217://ADDR:PORT[?baud=9600] for an RFC 2217 client (a Windows COM port "
                  "redirector, pySerial; one client at a time)")
      ->required();
  cmd->add_option("--upstream", args->upstream,
                  "The car: tcp://HOST:PORT, or pty:///dev/ttyUSB0 for a serial device")
      ->required();
  cmd->add_option("--faults", args->faults,
                  "Fault profile (YAML, see docs/faults.md); none: a clean pass-through");
  cmd->add_option("--seed", args->seed, "Seed for the fault rules (printed when chosen at random)");
  cmd->add_option("--log", args->wire_log,
                  "Write every byte of every link to this NDJSON wire log");
  cmd->add_option("--pcap", args->pcap, "Write the first link as a pcap (link N: NAME-N.pcap)");
  cmd->add_flag("-q,--quiet", args->quiet,
                "Print only the start line and errors, not each connection and fault");
  cmd->footer(
      "Examples:\n"
      "  hil proxy --protocol logi --listen tcp://127.0.0.1:9001 --upstream tcp://192.168.4.1:8080 "
      "\\\n"
      "            --faults scenarios/faults/sticky-packets.yaml --log wire.ndjson\n"
      "  hil proxy --protocol arduino --listen 'pty:///tmp/hil-arduino0?baud=9600' --upstream "
      "pty:///dev/ttyUSB0\n"
      "  hil proxy --protocol arduino --listen 'rfc2217://127.0.0.1:4000?baud=9600' \\\n"
      "            --upstream pty:///dev/ttyACM0   (a real board, shared with RFC 2217 clients)\n"
      "  hil proxy --protocol wr8 --profile svgui-head --listen tcp://127.0.0.1:5557 \\\n"
      "            --upstream tcp://127.0.0.1:5556 --log wire.ndjson   (the real vehicle program; "
      "frames\n"
      "            are its length byte and packet)\n"
      "Stops cleanly on Ctrl-C (SIGINT) or SIGTERM.");
  cmd->callback([&run, args] {
    run = [args]() -> int {
      link::ProxyOptions options;
      try {
        options.listen = link::parse_endpoint(args->listen);
        options.upstream = link::parse_endpoint(args->upstream);
        if (std::holds_alternative<link::Rfc2217Endpoint>(options.upstream)) {
          std::cerr << "hil proxy: --upstream " << args->upstream
                    << ": hil serves RFC 2217 (--listen rfc2217://...) but cannot connect to an "
                       "RFC 2217 server; give the car's serial port (pty:///dev/ttyUSB0) or "
                       "tcp://HOST:PORT\n";
          return 1;
        }
        if (!args->faults.empty()) options.faults = link::load_fault_profile(args->faults);
      } catch (const std::exception& e) {
        std::cerr << "hil proxy: " << e.what() << '\n';
        return 1;
      }
      try {
        options.protocol = link::protocol_adapter(args->protocol, args->profile);
      } catch (const protocol::ProfileError& e) {
        std::cerr << "hil proxy: --profile: " << e.what() << '\n';
        return 2;
      }
      options.seed = args->seed ? *args->seed : std::random_device{}();
      options.wire_log_path = args->wire_log;
      options.pcap_path = args->pcap;
      if (!args->quiet)
        options.log = [](const std::string& line) { std::cout << line << std::endl; };

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
        std::cerr << "hil proxy: cannot listen on " << args->listen << ": " << e.what() << '\n';
        return 1;
      }
      const auto* tcp = std::get_if<link::TcpEndpoint>(&options.listen);
      const auto* served = std::get_if<link::Rfc2217Endpoint>(&options.listen);
      const std::string host = tcp != nullptr ? tcp->host : served != nullptr ? served->host : "";
      if (!host.empty() && host != "127.0.0.1" && host != "localhost" && host != "::1") {
        std::cerr << "warning: listening on " << host << ", reachable from other machines\n";
      }
      std::cout << "hil proxy: clients connect to " << proxy.address() << ", car at "
                << link::to_uri(options.upstream) << ", protocol " << args->protocol
                << (options.protocol->profile().empty()
                        ? std::string()
                        : " (profile " + std::string(options.protocol->profile()) + ")")
                << ", " << options.faults.rules.size() << " fault rule(s), seed " << options.seed
                << " (replay with --seed " << options.seed << ")" << std::endl;
      signals.async_wait([&](const std::error_code& ec, int) {
        if (ec) return;
        std::cout << "hil proxy: stopping (" << proxy.links_opened() << " link(s) served, "
                  << proxy.connections_refused() << " refused)" << std::endl;
        proxy.close();
        executor.call_after(std::chrono::milliseconds(100), [&io] { io.stop(); });
      });
      io.run();
      return 0;
    };
  });
}

}  // namespace hil::apps
