#include "link/executor.hpp"

#include <stdexcept>

namespace hil::link {

Executor::TimerId VirtualExecutor::call_at(Time at, Task task) {
  if (at < now_) at = now_;
  const TimerId id = next_id_++;
  queue_.emplace(std::make_pair(at, id), std::move(task));
  due_.emplace(id, at);
  return id;
}

bool VirtualExecutor::cancel(TimerId id) {
  const auto it = due_.find(id);
  if (it == due_.end()) return false;
  queue_.erase(std::make_pair(it->second, id));
  due_.erase(it);
  return true;
}

bool VirtualExecutor::run_one() {
  if (queue_.empty()) return false;
  auto node = queue_.extract(queue_.begin());
  const auto [at, id] = node.key();
  due_.erase(id);
  now_ = at;
  // The task may schedule or cancel others; it owns nothing in the queue now.
  node.mapped()();
  return true;
}

std::size_t VirtualExecutor::run_until(Time until) {
  std::size_t ran = 0;
  while (!queue_.empty() && queue_.begin()->first.first <= until) {
    run_one();
    ++ran;
  }
  if (until > now_) now_ = until;
  return ran;
}

std::size_t VirtualExecutor::run_until_idle(std::size_t max_tasks) {
  std::size_t ran = 0;
  while (ran < max_tasks && run_one())
    ++ran;
  return ran;
}

std::optional<Time> VirtualExecutor::next_due() const {
  if (queue_.empty()) return std::nullopt;
  return queue_.begin()->first.first;
}

}  // namespace hil::link
