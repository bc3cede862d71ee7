#pragma once
// What the probe makers of conform/probes/ share: a builder that appends
// exchanges with the probe's usual listen window (or one of their own),
// so each car's file is its list of exchanges and little else.
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
  /// `frame` in one write.
  static std::vector<ProbeWrite> once(Bytes frame) {
    return {ProbeWrite{Duration{0}, std::move(frame)}};
  }
  /// `frame` one byte per write, `gap` apart.
  static std::vector<ProbeWrite> bytewise(const Bytes& frame, Duration gap) {
    std::vector<ProbeWrite> writes;
    for (const auto b : frame)
      writes.push_back({writes.empty() ? Duration{0} : gap, Bytes{b}});
    return writes;
  }

  /// `writes`, then the usual window.
  ProbeBuilder& add(std::string name, std::string what, ExchangeKind kind,
                    std::vector<ProbeWrite> writes) {
    return add(std::move(name), std::move(what), kind, std::move(writes), listen_);
  }
  /// `writes`, then `listen`; a `physical` answer is compared by shape.
  ProbeBuilder& add(std::string name, std::string what, ExchangeKind kind,
                    std::vector<ProbeWrite> writes, Duration listen, bool physical = false) {
    return add({std::move(name), std::move(what), kind, std::move(writes), physical, listen});
  }
  /// One write of `frame`, then the usual window.
  ProbeBuilder& send(std::string name, ExchangeKind kind, std::string what, Bytes frame) {
    return add(std::move(name), std::move(what), kind, once(std::move(frame)));
  }
  /// Several writes, each `gap` after the last.
  ProbeBuilder& send_pieces(std::string name, ExchangeKind kind, std::string what,
                            std::vector<Bytes> pieces, Duration gap) {
    std::vector<ProbeWrite> writes;
    for (auto& piece : pieces)
      writes.push_back({writes.empty() ? Duration{0} : gap, std::move(piece)});
    return add(std::move(name), std::move(what), kind, std::move(writes));
  }
  /// `frame` one byte per write, `gap` apart.
  ProbeBuilder& send_bytewise(std::string name, std::string what, const Bytes& frame,
                              Duration gap) {
    return add(std::move(name), std::move(what), ExchangeKind::framing, bytewise(frame, gap));
  }
  /// Opens the connection (closing it first when open), then listens.
  ProbeBuilder& connect(std::string name, std::string what) {
    return add(std::move(name), std::move(what), ExchangeKind::connect, {});
  }
  /// No writes: the car's own frames for `window`.
  ProbeBuilder& listen(std::string name, std::string what, Duration window) {
    return add(std::move(name), std::move(what), ExchangeKind::telemetry, {}, window);
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
