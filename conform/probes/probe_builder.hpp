#pragma once
// What the probe makers of conform/probes/ share: a builder that appends
// exchanges with the probe's usual listen window, so each car's file is
// its list of exchanges and little else.
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "conform/probe.hpp"

namespace hil::conform {

class ProbeBuilder {
 public:
  /// `listen` is every exchange's window unless one says otherwise.
  ProbeBuilder(std::string version, Duration settle, Duration listen) : listen_(listen) {
    probe_.version = std::move(version);
    probe_.settle = settle;
  }

  static Bytes bytes(std::string_view text) { return Bytes(text.begin(), text.end()); }
  static Bytes join(std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const auto& p : parts)
      out.insert(out.end(), p.begin(), p.end());
    return out;
  }

  /// One write of `frame`, then the usual window.
  ProbeBuilder& send(std::string name, ExchangeKind kind, std::string what, Bytes frame) {
    return add({std::move(name),
                std::move(what),
                kind,
                {{Duration{0}, std::move(frame)}},
                false,
                listen_});
  }
  /// Several writes, each `gap` after the last.
  ProbeBuilder& send_pieces(std::string name, ExchangeKind kind, std::string what,
                            std::vector<Bytes> pieces, Duration gap) {
    Exchange e{std::move(name), std::move(what), kind, {}, false, listen_};
    for (auto& piece : pieces)
      e.writes.push_back({e.writes.empty() ? Duration{0} : gap, std::move(piece)});
    return add(std::move(e));
  }
  /// `frame` one byte per write, `gap` apart.
  ProbeBuilder& send_bytewise(std::string name, std::string what, const Bytes& frame,
                              Duration gap) {
    std::vector<Bytes> pieces;
    for (const auto b : frame)
      pieces.push_back(Bytes{b});
    return send_pieces(std::move(name), ExchangeKind::framing, std::move(what), std::move(pieces),
                       gap);
  }
  /// Opens the connection (closing it first when open), then listens.
  ProbeBuilder& connect(std::string name, std::string what) {
    return add({std::move(name), std::move(what), ExchangeKind::connect, {}, false, listen_});
  }
  /// No writes: the car's own frames for `window`.
  ProbeBuilder& listen(std::string name, std::string what, Duration window) {
    return add({std::move(name), std::move(what), ExchangeKind::telemetry, {}, false, window});
  }
  /// Marks the last exchange's answer as physical (compared by shape).
  ProbeBuilder& physical() {
    probe_.exchanges.back().physical = true;
    return *this;
  }
  /// Sets the last exchange's window.
  ProbeBuilder& window(Duration listen) {
    probe_.exchanges.back().listen = listen;
    return *this;
  }
  ProbeBuilder& add(Exchange exchange) {
    probe_.exchanges.push_back(std::move(exchange));
    return *this;
  }
  Probe take(std::vector<std::string> telemetry_kinds = {}) {
    probe_.telemetry_kinds = std::move(telemetry_kinds);
    return std::move(probe_);
  }

 private:
  Probe probe_;
  Duration listen_;
};

}  // namespace hil::conform
