#pragma once
// In-memory byte pipes (mem://name) for the virtual-time driver and for
// tests: bytes written at one end reach the other end as a task on the
// executor, in order, in the pieces they were written; on a paced line
// (mem://name?baud=N) each byte arrives once its last bit is sent, as on a
// serial line (link/serial_pacer.hpp), in the chunks due at each tick. A
// half-close (shutdown_send) reaches a peer end that takes on_end as
// on_end, after the bytes written before it; close() is always a close.

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"

namespace hil::link {

/// Two connected ends; `baud` paces both directions (0: unpaced).
std::pair<BytePipePtr, BytePipePtr> make_mem_pipe(Executor& executor, const std::string& name,
                                                  unsigned baud = 0);

/// A registry of mem:// listeners, one per name, on one executor.
class MemNetwork {
 public:
  explicit MemNetwork(Executor& executor) : executor_(executor) {}

  /// Throws EndpointError if the name is already listened on. `baud`
  /// paces every connection to it (0: unpaced).
  std::unique_ptr<Listener> listen(const std::string& name, unsigned baud = 0);
  /// Connects to a listener, on a line paced at the listener's baud; the
  /// handler gets connection_refused (as a task) when nothing listens on
  /// the name.
  void connect(const std::string& name, ConnectHandler handler);

  Executor& executor() { return executor_; }

 private:
  friend class MemListener;
  struct Entry;
  Executor& executor_;
  std::map<std::string, std::shared_ptr<Entry>> listeners_;
};

}  // namespace hil::link
