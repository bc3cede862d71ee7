#pragma once
// The fleet load driver's view of processes: `hil mock logi --count N` as a
// child process, and what /proc and getrusage say about it, this driver and
// the machine.

#include <sys/resource.h>
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

namespace hil::bench::fleet {

/// What /proc says about a process at one moment.
struct ProcSample {
  double cpu_s = 0;  ///< user + sys
  /// Time the process's threads were runnable but waited for a core (the
  /// machine's load as the process felt it).
  double run_delay_s = 0;
  double rss_kib = 0;
  std::size_t fds = 0;
};

ProcSample sample(pid_t pid);

/// "0.52 0.61 0.70": the load averages of /proc/loadavg.
std::string loadavg();

/// The CPU's model name from /proc/cpuinfo.
std::string cpu_name();

/// Raises this process's open-file limit to its hard limit.
void raise_fd_limit();

/// How many files this process may open.
rlim_t fd_limit();

/// CPU seconds (user + sys) this process has used.
double driver_cpu_s();

/// `hil mock logi --count N --port 0` as a child process; its output goes
/// to a log file in `dir`, read back when it fails.
class MockProcess {
 public:
  MockProcess(const std::string& hil, std::size_t count, const std::string& dir);
  ~MockProcess() { stop(); }
  MockProcess(const MockProcess&) = delete;
  MockProcess& operator=(const MockProcess&) = delete;

  pid_t pid() const { return pid_; }

  /// The cars' ports once every car listens; empty when the mock exited or
  /// `limit` passed.
  std::vector<unsigned> wait_for_ports(std::chrono::seconds limit);

  /// What the mock wrote to stdout and stderr.
  std::string output() const;

  /// SIGINT, then SIGKILL when it has not exited within 5 s.
  void stop();

 private:
  pid_t pid_ = -1;
  std::string ports_file_;
  std::string log_file_;
};

}  // namespace hil::bench::fleet
