#include "link/executor.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

namespace hil::link {

namespace {

constexpr Executor::TimerId id_of(std::uint32_t slot, std::uint32_t generation) {
  return (static_cast<Executor::TimerId>(generation) << 32) | slot;
}

}  // namespace

Executor::TimerId VirtualExecutor::call_at(Time at, Task task) {
  if (at < now_) at = now_;
  std::uint32_t slot = 0;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    if (slots_.size() >= std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("VirtualExecutor: too many pending tasks");
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
  }
  Slot& s = slots_[slot];
  s.task = std::move(task);
  s.pending = true;
  ++live_;
  // Generation 0 is never handed out, so no TimerId is 0 (callers use 0 for
  // "no timer").
  heap_.push_back(Entry{at, next_seq_++, slot, s.generation});
  std::push_heap(heap_.begin(), heap_.end(), later);
  return id_of(slot, s.generation);
}

void VirtualExecutor::release(std::uint32_t slot) {
  Slot& s = slots_[slot];
  s.pending = false;
  // Skip 0 when the generation wraps (after 4 billion reuses of one slot).
  if (++s.generation == 0) s.generation = 1;
  free_.push_back(slot);
  --live_;
}

bool VirtualExecutor::cancel(TimerId id) {
  const auto slot = static_cast<std::uint32_t>(id & 0xffff'ffffu);
  const auto generation = static_cast<std::uint32_t>(id >> 32);
  if (slot >= slots_.size()) return false;
  Slot& s = slots_[slot];
  if (!s.pending || s.generation != generation) return false;
  // The task's captures go now, as they would if it had run.
  Task task = std::move(s.task);
  s.task = nullptr;
  release(slot);
  // Stale entries are skipped as they come up; when they outnumber the
  // live ones (timeouts re-armed far ahead, again and again), drop them.
  if (heap_.size() > 64 && heap_.size() > 2 * live_) {
    std::erase_if(heap_, [this](const Entry& e) { return stale(e); });
    std::make_heap(heap_.begin(), heap_.end(), later);
  }
  return true;
}

void VirtualExecutor::drop_stale_top() const {
  while (!heap_.empty() && stale(heap_.front())) {
    std::pop_heap(heap_.begin(), heap_.end(), later);
    heap_.pop_back();
  }
}

bool VirtualExecutor::run_one() {
  drop_stale_top();
  if (heap_.empty()) return false;
  std::pop_heap(heap_.begin(), heap_.end(), later);
  const Entry e = heap_.back();
  heap_.pop_back();
  // The task may schedule or cancel others; it owns nothing in the queue now.
  Task task = std::move(slots_[e.slot].task);
  slots_[e.slot].task = nullptr;
  release(e.slot);
  now_ = e.at;
  task();
  return true;
}

std::size_t VirtualExecutor::run_until(Time until) {
  std::size_t ran = 0;
  for (auto due = next_due(); due && *due <= until; due = next_due()) {
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
  drop_stale_top();
  if (heap_.empty()) return std::nullopt;
  return heap_.front().at;
}

WakeupTimer::WakeupTimer(Executor& executor, Executor::Task fire)
    : executor_(executor), fire_(std::move(fire)) {}

WakeupTimer::~WakeupTimer() {
  *alive_ = false;
  if (id_ != 0) executor_.cancel(id_);
}

void WakeupTimer::schedule(std::optional<Time> due) {
  if (due == due_ && (id_ != 0 || !due)) return;
  if (id_ != 0) executor_.cancel(id_);
  id_ = 0;
  due_ = due;
  if (!due) return;
  id_ = executor_.call_at(*due, [this, alive = alive_] {
    if (!*alive) return;
    id_ = 0;
    due_.reset();
    fire_();
  });
}

}  // namespace hil::link
