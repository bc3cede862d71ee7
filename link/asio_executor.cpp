#include "link/asio_executor.hpp"

#include <asio/error.hpp>

namespace hil::link {

AsioExecutor::AsioExecutor(asio::io_context& io) : io_(io), timer_(io) {}

AsioExecutor::~AsioExecutor() {
  timer_.cancel();
}

Executor::TimerId AsioExecutor::call_at(Time at, Task task) {
  // As in VirtualExecutor: a time that has passed means now, so a task
  // scheduled late runs after those already due, not before them.
  const Time current = now();
  if (at < current) at = current;
  const TimerId id = next_id_++;
  queue_.emplace(std::pair{at, id}, std::move(task));
  due_.emplace(id, at);
  if (!armed_for_ || at < *armed_for_) arm();
  return id;
}

bool AsioExecutor::cancel(TimerId id) {
  const auto it = due_.find(id);
  if (it == due_.end()) return false;
  queue_.erase(std::pair{it->second, id});
  due_.erase(it);
  // The timer stays armed for the cancelled task's time; it then finds
  // nothing due and re-arms for the next one. Cheaper than re-arming here,
  // except when nothing is left: then io_context::run() may return.
  if (queue_.empty()) {
    armed_for_.reset();
    timer_.cancel();
  }
  return true;
}

void AsioExecutor::arm() {
  if (queue_.empty()) {
    armed_for_.reset();
    timer_.cancel();
    return;
  }
  armed_for_ = queue_.begin()->first.first;
  timer_.expires_at(time_point(*armed_for_));
  timer_.async_wait([this, alive = std::weak_ptr<int>(alive_)](std::error_code ec) {
    // operation_aborted: re-armed for an earlier task, or shutting down.
    if (ec == asio::error::operation_aborted || alive.expired()) return;
    run_due();
  });
}

void AsioExecutor::run_due() {
  armed_for_.reset();
  // Everything due when this batch starts runs now. Tasks scheduled by
  // these tasks are due later than batch_now and wait for the next turn of
  // the io_context, so I/O handlers interleave and a task that reposts
  // itself cannot starve them.
  const Time batch_now = now();
  std::weak_ptr<int> alive = alive_;
  while (!queue_.empty() && queue_.begin()->first.first <= batch_now) {
    auto node = queue_.extract(queue_.begin());
    due_.erase(node.key().second);
    node.mapped()();
    if (alive.expired()) return;  // a task destroyed this executor
  }
  if (!armed_for_) arm();
}

}  // namespace hil::link
