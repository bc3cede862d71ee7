#pragma once
// Runs a probe against an endpoint on a run driver's executor: the same
// code probes a real car in real time (tcp://, pty://) and hil's mock in
// virtual time (mem://), so the two captures differ only where the cars do.
#include <optional>
#include <string>

#include "conform/probe.hpp"
#include "harness/run_driver.hpp"
#include "link/capture/probe_capture.hpp"
#include "link/endpoint.hpp"

namespace hil::conform {

/// The header a probe's capture starts with.
link::CaptureHeader capture_header(const Probe& probe, std::string target,
                                   std::int64_t started_wall_us);

struct ProbeRun {
  Capture capture;
  /// Why the probe stopped before its last exchange (the car could not be
  /// reached, or stopped answering the connection); the capture keeps
  /// everything up to there.
  std::optional<std::string> error;
};

struct ProbeHooks {
  /// Told of each exchange as it starts ("exchange 3/41 ping").
  std::function<void(const std::string&)> progress;
  /// Asked before each exchange and each write: once it says true, the
  /// probe goes straight to its closing stop exchange (a person pressed
  /// Ctrl-C; the car must not be left moving) and reports it interrupted.
  std::function<bool()> interrupted;
};

/// Runs every exchange of `probe` against `target` on `driver`, recording
/// into `recorder`; returns when the last exchange has ended or the probe
/// cannot go on.
ProbeRun run_probe(harness::RunDriver& driver, const link::Endpoint& target, const Probe& probe,
                   CaptureRecorder& recorder, const ProbeHooks& hooks = {});

}  // namespace hil::conform
