#include "link/faults/delivery_queue.hpp"

#include <algorithm>
#include <utility>

namespace hil::link::faults {

Time DeliveryQueue::after_stalls(Time t) const {
  // Stalls may chain or overlap, so repeat until t is in none of them.
  for (bool moved = true; moved;) {
    moved = false;
    for (const auto& s : stalls_) {
      if (t >= s.begin && t < s.end) {
        t = s.end;
        moved = true;
      }
    }
  }
  return t;
}

Time DeliveryQueue::slot(Time desired) const {
  return after_stalls(std::max(desired, last_due_));
}

Time DeliveryQueue::pace(Time t, std::size_t bytes, std::uint64_t rate) {
  const auto n = static_cast<std::uint64_t>(bytes);
  const auto on_line_ns = (n * 1'000'000'000ULL + rate - 1) / rate;
  const Time start = std::max(t, line_free_);
  const Time arrive = start + Duration{static_cast<Duration::rep>(on_line_ns)};
  line_free_ = arrive;
  return after_stalls(arrive);
}

bool DeliveryQueue::join(Time due, protocol::ByteView bytes, std::uint64_t push) {
  if (queue_.empty()) return false;
  Pending& last = queue_.back();
  if (!last.joinable || !last.bytes || last.push != push || last.due != due) return false;
  last.bytes->insert(last.bytes->end(), bytes.begin(), bytes.end());
  return true;
}

void DeliveryQueue::add(Time due, protocol::Bytes bytes, std::uint64_t push, bool joinable) {
  last_due_ = due;
  queue_.push_back(Pending{due, std::move(bytes), false, push, joinable});
}

void DeliveryQueue::add_break(Time at, bool reset) {
  queue_.push_back(Pending{at, std::nullopt, reset});
}

protocol::Bytes DeliveryQueue::cut_after(Time at) {
  protocol::Bytes lost;
  auto cut =
      std::find_if(queue_.begin(), queue_.end(), [&](const Pending& p) { return p.due > at; });
  for (auto it = cut; it != queue_.end(); ++it) {
    if (it->bytes) lost.insert(lost.end(), it->bytes->begin(), it->bytes->end());
  }
  queue_.erase(cut, queue_.end());
  return lost;
}

void DeliveryQueue::add_stall(Time begin, Time end, bool timed) {
  stalls_.push_back(Interval{begin, end, timed});
  // after_stalls never reorders (it maps a time to one no earlier, and a
  // later time to one no earlier than that), so the queue stays sorted.
  for (auto& p : queue_)
    p.due = after_stalls(p.due);
  last_due_ = after_stalls(last_due_);
}

void DeliveryQueue::forget_timed_stalls(Time from) {
  std::erase_if(stalls_, [&](const Interval& s) { return s.timed && s.begin >= from; });
}

void DeliveryQueue::pop_due(Time now, std::vector<InjectorOutput>& out) {
  while (!queue_.empty() && queue_.front().due <= now) {
    auto& p = queue_.front();
    if (p.bytes) {
      out.emplace_back(Delivery{std::move(*p.bytes)});
    } else {
      out.emplace_back(LinkBreak{p.reset});
    }
    queue_.pop_front();
  }
}

std::optional<Time> DeliveryQueue::next_due() const {
  if (queue_.empty()) return std::nullopt;
  return queue_.front().due;
}

}  // namespace hil::link::faults
