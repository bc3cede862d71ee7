#pragma once
// In-memory byte pipes (mem://name) for the virtual-time driver and for
// tests: bytes written at one end reach the other end as a task on the
// executor, in order, in the pieces they were written.

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"

namespace hil::link {

/// Two connected ends.
std::pair<BytePipePtr, BytePipePtr> make_mem_pipe(Executor& executor, const std::string& name);

/// A registry of mem:// listeners, one per name, on one executor.
class MemNetwork {
 public:
  explicit MemNetwork(Executor& executor) : executor_(executor) {}

  /// Throws EndpointError if the name is already listened on.
  std::unique_ptr<Listener> listen(const std::string& name);
  /// Connects to a listener; the handler gets connection_refused (as a task)
  /// when nothing listens on the name.
  void connect(const std::string& name, ConnectHandler handler);

  Executor& executor() { return executor_; }

 private:
  friend class MemListener;
  struct Entry;
  Executor& executor_;
  std::map<std::string, std::shared_ptr<Entry>> listeners_;
};

}  // namespace hil::link
