#include "link/link.hpp"

#include <utility>

#include "base/enum_names.hpp"

namespace hil::link {
namespace {

constexpr std::size_t index(Direction d) {
  return static_cast<std::size_t>(d);
}
constexpr Direction kDirections[] = {Direction::to_car, Direction::to_client};

std::string side_name(Direction sender) {
  return sender == Direction::to_car ? "client" : "car";
}
LinkClose::By side_of(Direction sender) {
  return sender == Direction::to_car ? LinkClose::By::client : LinkClose::By::car;
}

}  // namespace

constexpr auto kLinkCloseByNames =
    base::enum_names<LinkClose::By>({LinkClose::By::client, "client"}, {LinkClose::By::car, "car"},
                                    {LinkClose::By::fault, "fault"}, {LinkClose::By::hil, "hil"});

std::string_view to_string(LinkClose::By by) {
  return kLinkCloseByNames.name(by, "hil");
}

std::shared_ptr<Link> Link::create(Executor& executor, BytePipePtr client, BytePipePtr car,
                                   LinkOptions options) {
  return std::shared_ptr<Link>(
      new Link(executor, std::move(client), std::move(car), std::move(options)));
}

Link::Link(Executor& executor, BytePipePtr client, BytePipePtr car, LinkOptions options)
    : executor_(executor), observers_(std::move(options.observers)) {
  pipes_[index(Direction::to_car)] = std::move(car);
  pipes_[index(Direction::to_client)] = std::move(client);
  auto protocol = options.protocol ? options.protocol : protocol_adapter("raw");
  const auto sink = [this](const FaultEvent& e) {
    ++stats_.faults;
    for (const auto& o : observers_)
      o->on_fault(e);
  };
  injectors_[index(Direction::to_car)] = std::make_unique<FaultInjector>(
      Direction::to_car, protocol, std::move(options.to_car), options.seed, sink, executor.now());
  injectors_[index(Direction::to_client)] =
      std::make_unique<FaultInjector>(Direction::to_client, protocol, std::move(options.to_client),
                                      options.seed, sink, executor.now());
}

Link::~Link() {
  for (const auto d : kDirections) {
    if (timers_[index(d)] != 0) executor_.cancel(timers_[index(d)]);
  }
}

void Link::start() {
  start(executor_.now());
}

void Link::start(Time opened_at) {
  if (open_) return;
  open_ = true;
  for (const auto& o : observers_) {
    o->on_open(opened_at, pipes_[index(Direction::to_client)]->describe(),
               pipes_[index(Direction::to_car)]->describe());
  }
  // Bytes the client sends travel to_car; bytes the car sends travel to_client.
  for (const auto d : kDirections) {
    // pipes_ is indexed by the direction a pipe receives; it sends the other.
    const Direction sender = d == Direction::to_car ? Direction::to_client : Direction::to_car;
    std::weak_ptr<Link> weak = weak_from_this();
    pipes_[index(sender)]->start(BytePipe::Handlers{[weak, d](ByteView bytes) {
                                                      if (auto self = weak.lock())
                                                        self->on_bytes(d, bytes);
                                                    },
                                                    [weak, d](std::error_code ec) {
                                                      if (auto self = weak.lock())
                                                        self->on_side_closed(d, ec);
                                                    },
                                                    [weak, d] {
                                                      if (auto self = weak.lock())
                                                        self->on_side_ended(d, Ended::half);
                                                    }});
  }
  // Timed rules (a reset at 7 s, a stall at 5 s) fire even on a quiet link.
  for (const auto d : kDirections)
    schedule(d);
}

void Link::on_bytes(Direction d, ByteView bytes) {
  if (!open_) return;
  const Time now = executor_.now();
  stats_.bytes_sent[index(d)] += bytes.size();
  for (const auto& o : observers_)
    o->on_sent(now, d, bytes);
  injectors_[index(d)]->push(now, bytes);
  pump(d);
}

void Link::pump(Direction d) {
  if (!open_) return;
  const Time now = executor_.now();
  scratch_.clear();
  injectors_[index(d)]->poll(now, scratch_);
  // Outputs are moved out first: observers or a break may re-enter the link.
  std::vector<InjectorOutput> outputs;
  outputs.swap(scratch_);
  for (auto& output : outputs) {
    if (auto* delivery = std::get_if<Delivery>(&output)) {
      stats_.bytes_delivered[index(d)] += delivery->bytes.size();
      pipes_[index(d)]->write(delivery->bytes);
      for (const auto& o : observers_)
        o->on_delivered(now, d, delivery->bytes);
    } else {
      const bool reset = std::get<LinkBreak>(output).reset;
      shut(LinkClose{LinkClose::By::fault, reset ? CloseMode::reset : CloseMode::graceful,
                     std::string("fault injected: ") + (reset ? "reset" : "disconnect") + " (" +
                         std::string(to_string(d)) + ")"});
      return;
    }
  }
  hold_back_if_full(d);
  if (ended_[index(d)] != Ended::no && !passed_[index(d)] && !injectors_[index(d)]->next_due()) {
    pass_end(d);
    return;
  }
  schedule(d);
}

void Link::schedule(Direction d) {
  const auto next = injectors_[index(d)]->next_due();
  auto& timer = timers_[index(d)];
  if (next && timer != 0 && timer_due_[index(d)] == *next) return;
  if (timer != 0) {
    executor_.cancel(timer);
    timer = 0;
  }
  if (!next) return;
  timer_due_[index(d)] = *next;
  std::weak_ptr<Link> weak = weak_from_this();
  timer = executor_.call_at(*next, [weak, d] {
    if (auto self = weak.lock()) {
      self->timers_[index(d)] = 0;
      self->pump(d);
    }
  });
}

void Link::hold_back_if_full(Direction d) {
  BytePipe& receiver = *pipes_[index(d)];
  if (held_back_[index(d)] || receiver.queued_bytes() <= kLinkHighWaterBytes) return;
  // pipes_ is indexed by the direction a pipe receives: the sender of d's
  // bytes is the other pipe.
  const Direction other = d == Direction::to_car ? Direction::to_client : Direction::to_car;
  held_back_[index(d)] = true;
  ++stats_.holds[index(d)];
  pipes_[index(other)]->pause_reading();
  std::weak_ptr<Link> weak = weak_from_this();
  receiver.when_drained_to(kLinkLowWaterBytes, [weak, d, other] {
    const auto self = weak.lock();
    if (!self || !self->held_back_[index(d)]) return;
    self->held_back_[index(d)] = false;
    if (self->open_) self->pipes_[index(other)]->resume_reading();
  });
}

void Link::on_side_closed(Direction d, std::error_code ec) {
  if (!open_) return;
  if (ec && ec != end_of_stream() && ec != closed_here()) {
    shut(LinkClose{side_of(d), CloseMode::reset,
                   side_name(d) + " connection failed: " + ec.message()});
    return;
  }
  // The sender closed outright (eof from a pipe without half-closes), or
  // a receiver that could not half-close was closed instead
  // (closed_here()). After on_end, eof is only the pipe closing itself
  // once both of its directions ended: nothing new then.
  on_side_ended(d, Ended::closed);
}

void Link::on_side_ended(Direction d, Ended how) {
  if (!open_ || ended_[index(d)] != Ended::no) return;
  // The sender has ended; what it sent and the injector still holds
  // (delays, a partial frame, a slow close) is delivered before the end is
  // passed on.
  const Direction other = d == Direction::to_car ? Direction::to_client : Direction::to_car;
  if (ended_[index(other)] == Ended::no) first_ended_ = d;
  ended_[index(d)] = how;
  injectors_[index(d)]->finish(executor_.now());
  pump(d);
}

void Link::pass_end(Direction d) {
  const Direction other = d == Direction::to_car ? Direction::to_client : Direction::to_car;
  if (passed_[index(other)]) {
    // The other direction's end was passed on already: both are over. The
    // receiver gets this end as it got the first (on_end for a TCP or mem
    // peer), after what was delivered, then the link closes.
    pipes_[index(d)]->shutdown_send();
    const Direction second = first_ended_ == d ? other : d;
    shut(LinkClose{side_of(first_ended_), CloseMode::graceful,
                   side_name(first_ended_) + " and " + side_name(second) + " closed"});
    return;
  }
  if (ended_[index(d)] == Ended::closed) {
    // The sender closed outright (or cannot half-close): it reads nothing
    // more, so the link ends, as it always did.
    shut(LinkClose{side_of(d), CloseMode::graceful, side_name(d) + " closed"});
    return;
  }
  passed_[index(d)] = true;
  pipes_[index(d)]->shutdown_send();
  if (!pipes_[index(d)]->is_open() && ended_[index(other)] == Ended::no) {
    // The receiver cannot half-close (a pty): it was closed instead, and
    // the link ends with it. (A receiver whose own peer has ended closes
    // itself here: the other direction still finishes.)
    shut(LinkClose{side_of(d), CloseMode::graceful, side_name(d) + " closed"});
    return;
  }
  const Time now = executor_.now();
  for (const auto& o : observers_)
    o->on_half_close(now, d);
}

void Link::shut(LinkClose close) {
  if (!open_) return;
  open_ = false;
  for (const auto d : kDirections) {
    if (timers_[index(d)] != 0) {
      executor_.cancel(timers_[index(d)]);
      timers_[index(d)] = 0;
    }
    pipes_[index(d)]->close(close.mode);
  }
  const Time now = executor_.now();
  for (const auto& o : observers_)
    o->on_close(now, close);
}

void Link::close(CloseMode mode) {
  shut(LinkClose{LinkClose::By::hil, mode, "closed by hil"});
}

bool Link::is_open() const {
  return open_;
}

void Link::set_profile(Direction direction, FaultProfile profile) {
  injectors_[index(direction)]->set_profile(std::move(profile));
  pump(direction);
}

void Link::set_faults(const FaultProfile& profile) {
  for (const auto d : {Direction::to_car, Direction::to_client})
    set_profile(d, for_direction(profile, d));
}

LinkStats Link::stats() const {
  return stats_;
}

}  // namespace hil::link
