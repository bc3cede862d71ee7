#pragma once
// A conformance probe: the fixed sequence of exchanges hil sends a car to
// find out how it behaves, the same against a real car (`hil conform
// probe`) and against hil's mock in virtual time (`hil conform check`).
// Each exchange is a few writes at set delays and a window in which the
// car's answer is collected; nothing in a probe depends on what the car
// answered, so two runs of one probe are comparable exchange by exchange.
// The exchanges of each car are listed in docs/conformance.md.
#include <string>
#include <string_view>
#include <vector>

#include "link/capture/probe_capture.hpp"
#include "link/time.hpp"
#include "mocks/car.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::conform {

using link::Duration;
using link::Time;
using protocol::Bytes;

/// One write of an exchange: `bytes` written `after` the previous write of
/// the exchange (or the exchange's start).
struct ProbeWrite {
  Duration after{0};
  Bytes bytes;
};

using link::Capture;
using link::CapturedExchange;
using link::CaptureEvent;
using link::CaptureRecorder;
using link::ExchangeKind;

struct Exchange {
  std::string name;  ///< unique in its probe: "ping", "v-max", "bad-checksum"
  std::string what;  ///< one line for a person
  ExchangeKind kind = ExchangeKind::command;
  std::vector<ProbeWrite> writes;
  /// The answer's fields come from the physical world (a distance, the
  /// battery, the time a move has left): it is compared by shape (kind,
  /// validity, and the text with each run of digits as one, or the length
  /// of a binary frame) rather than byte for byte. Telemetry always is.
  bool physical = false;
  /// How long after the last write (or the start, without writes) the car's
  /// bytes are collected for this exchange.
  Duration listen{0};
};

/// Everything the probe of one car sends.
struct Probe {
  mocks::CarKind car = mocks::CarKind::logi;
  /// The profile the probe's frames are written in (WR8 and Leka frame
  /// their requests by profile; LOGI and Arduino send the same bytes for
  /// every profile and test what tells them apart).
  std::string profile;
  /// "<car>-probe/<n>": a capture is checked only by the probe that made it.
  std::string version;
  /// After the connection opens (and after each reconnect), before the first
  /// write: a serial board restarts when its port opens.
  Duration settle{0};
  /// Frame kinds the car sends on its own (LOGI STAT, WR8 DATA): they are
  /// compared by their period in telemetry exchanges and left out of the
  /// answers elsewhere.
  std::vector<std::string> telemetry_kinds;
  /// The first is always a `connect` exchange.
  std::vector<Exchange> exchanges;

  /// The probe's length when the car answers at once: settle, every write's
  /// delay and every listen window.
  Duration duration() const;
};

/// The probe of `car` in `profile` (empty: the car's default). Throws
/// protocol::ProfileError for a profile the car does not have.
Probe make_probe(mocks::CarKind car, std::string_view profile);

/// The version string make_probe gives `car` ("logi-probe/1").
std::string probe_version(mocks::CarKind car);

// One maker per car (conform/probes/*.cpp); `profile` is already checked.
Probe make_logi_probe(std::string_view profile);
Probe make_wr8_probe(std::string_view profile);
Probe make_arduino_probe(std::string_view profile);
Probe make_leka_probe(std::string_view profile);

}  // namespace hil::conform
