#include "link/endpoint.hpp"

#include <charconv>

#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::link {
namespace {

[[noreturn]] void fail(std::string_view uri, const std::string& what) {
  throw EndpointError("endpoint '" + std::string(uri) + "': " + what);
}

unsigned long long number(std::string_view uri, std::string_view text, const char* what,
                          unsigned long long max) {
  unsigned long long v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || end != text.data() + text.size() || v > max) {
    fail(uri, std::string(what) + " '" + std::string(text) + "' is not a number 0.." +
                  std::to_string(max));
  }
  return v;
}

TcpEndpoint parse_tcp(std::string_view uri, std::string_view rest,
                      std::string_view scheme = "tcp") {
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string_view::npos || colon + 1 == rest.size()) {
    fail(uri, "expected " + std::string(scheme) + "://HOST:PORT, e.g. " + std::string(scheme) +
                  "://127.0.0.1:" + (scheme == "tcp" ? "9000" : "4000"));
  }
  std::string_view host = rest.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  if (host.empty()) fail(uri, "the host is empty (use 127.0.0.1 for this machine only)");
  TcpEndpoint e;
  e.host = std::string(host);
  e.port = static_cast<std::uint16_t>(number(uri, rest.substr(colon + 1), "port", 65535));
  return e;
}

/// The `?key=value&...` options of a URI, each handed to `option(key, value)`.
template <typename Option>
void parse_options(std::string_view query, Option option) {
  for (const std::string_view item : protocol::split(query, '&')) {
    const std::size_t eq = item.find('=');
    option(item.substr(0, eq),
           eq == std::string_view::npos ? std::string_view{} : item.substr(eq + 1));
  }
}

constexpr unsigned long long kMaxBaud = 4'000'000;

// A serial line's options, "baud=N&reset_ms=N", into `e` (a pty's or an
// RFC 2217 port's).
template <class SerialEndpoint>
void parse_serial_options(std::string_view uri, std::string_view query, SerialEndpoint& e) {
  parse_options(query, [&](std::string_view key, std::string_view value) {
    if (key == "baud") {
      e.baud = static_cast<unsigned>(number(uri, value, "baud", kMaxBaud));
    } else if (key == "reset_ms") {
      e.reset_on_open = milliseconds(number(uri, value, "reset_ms", 60'000));
    } else {
      fail(uri, "unknown option '" + std::string(key) + "' (known: baud, reset_ms)");
    }
  });
}

PtyEndpoint parse_pty(std::string_view uri, std::string_view rest) {
  const std::size_t q = rest.find('?');
  PtyEndpoint e;
  e.path = std::string(rest.substr(0, q));
  if (e.path.empty() || e.path.front() != '/') {
    fail(uri, "expected pty:///ABSOLUTE/PATH (three slashes), e.g. pty:///tmp/hil-arduino0");
  }
  if (q != std::string_view::npos) parse_serial_options(uri, rest.substr(q + 1), e);
  return e;
}

MemEndpoint parse_mem(std::string_view uri, std::string_view rest) {
  const std::size_t q = rest.find('?');
  MemEndpoint e;
  e.name = std::string(rest.substr(0, q));
  if (e.name.empty()) fail(uri, "expected mem://NAME, e.g. mem://car0 or mem://car0?baud=9600");
  if (q == std::string_view::npos) return e;
  parse_options(rest.substr(q + 1), [&](std::string_view key, std::string_view value) {
    if (key != "baud") fail(uri, "unknown option '" + std::string(key) + "' (known: baud)");
    e.baud = static_cast<unsigned>(number(uri, value, "baud", kMaxBaud));
  });
  return e;
}

Rfc2217Endpoint parse_rfc2217(std::string_view uri, std::string_view rest) {
  const std::size_t q = rest.find('?');
  std::string_view authority = rest.substr(0, q);
  // "rfc2217://:4000": this machine only, as a listener's default.
  const std::string local = authority.starts_with(':') ? "127.0.0.1" + std::string(authority) : "";
  if (!local.empty()) authority = local;
  const TcpEndpoint where = parse_tcp(uri, authority, "rfc2217");
  Rfc2217Endpoint e;
  e.host = where.host;
  e.port = where.port;
  if (q != std::string_view::npos) parse_serial_options(uri, rest.substr(q + 1), e);
  return e;
}

/// "?baud=N&reset_ms=N" for the options that are set, or nothing.
std::string serial_query(unsigned baud, Duration reset_on_open) {
  std::string query;
  std::string sep = "?";
  if (baud != 0) {
    query += sep + "baud=" + std::to_string(baud);
    sep = "&";
  }
  if (reset_on_open.count() != 0) {
    query += sep + "reset_ms=" +
             std::to_string(std::chrono::duration_cast<milliseconds>(reset_on_open).count());
  }
  return query;
}

std::string host_port(const std::string& host, std::uint16_t port) {
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

}  // namespace

Endpoint parse_endpoint(std::string_view uri) {
  const std::size_t sep = uri.find("://");
  if (sep == std::string_view::npos) {
    fail(uri,
         "expected a URI such as tcp://127.0.0.1:9000, pty:///tmp/hil-arduino0, mem://car0 or "
         "rfc2217://127.0.0.1:4000");
  }
  const std::string_view scheme = uri.substr(0, sep);
  const std::string_view rest = uri.substr(sep + 3);
  if (scheme == "tcp") return parse_tcp(uri, rest);
  if (scheme == "pty") return parse_pty(uri, rest);
  if (scheme == "mem") return parse_mem(uri, rest);
  if (scheme == "rfc2217") return parse_rfc2217(uri, rest);
  fail(uri, "unknown scheme '" + std::string(scheme) + "' (known: tcp, pty, mem, rfc2217)");
}

std::string to_uri(const Endpoint& endpoint) {
  return std::visit(
      protocol::Overloaded{
          [](const TcpEndpoint& e) { return "tcp://" + host_port(e.host, e.port); },
          [](const PtyEndpoint& e) {
            return "pty://" + e.path + serial_query(e.baud, e.reset_on_open);
          },
          [](const MemEndpoint& e) {
            return "mem://" + e.name + (e.baud != 0 ? "?baud=" + std::to_string(e.baud) : "");
          },
          [](const Rfc2217Endpoint& e) {
            return "rfc2217://" + host_port(e.host, e.port) + serial_query(e.baud, e.reset_on_open);
          }},
      endpoint);
}

}  // namespace hil::link
