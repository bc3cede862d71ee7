#include "link/proxy.hpp"

#include <algorithm>
#include <deque>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "link/capture/pcap.hpp"
#include "link/capture/wire_log.hpp"

namespace hil::link {
namespace {

constexpr std::size_t slot_of(Direction d) {
  return static_cast<std::size_t>(d);
}
constexpr Direction kProxyDirections[] = {Direction::to_car, Direction::to_client};

// Prints connections and faults as they happen.
class TerminalObserver final : public LinkObserver {
 public:
  TerminalObserver(std::string id, std::function<void(const std::string&)> log)
      : id_(std::move(id)), log_(std::move(log)) {}
  void on_fault(const FaultEvent& e) override {
    log_(id_ + " " + format_ms(e.at) + " fault " + std::string(to_string(e.kind)) + " (" + e.rule +
         ", " + std::string(to_string(e.direction)) + "): " + e.detail);
  }
  void on_sent(Time /*at*/, Direction d, protocol::ByteView bytes) override {
    (d == Direction::to_car ? to_car_ : to_client_) += bytes.size();
  }
  void on_open(Time /*at*/, const std::string& client, const std::string& car) override {
    client_ = client;
    car_ = car;
  }
  void on_half_close(Time at, Direction d) override {
    const bool client = d == Direction::to_car;
    log_(id_ + " " + format_ms(at) + " " + (client ? "client" : "car") +
         " ended its stream (half-close passed on); the " + (client ? "car" : "client") +
         " may still send");
  }
  void on_close(Time at, const LinkClose& close) override {
    if (close.reason.find(std::make_error_code(std::errc::no_buffer_space).message()) !=
        std::string::npos) {
      const bool client = close.by == LinkClose::By::client;
      log_(id_ + " " + format_ms(at) + " " + (client ? "client" : "car") +
           " dropped: it stopped reading and " + std::to_string(kMaxSendBacklogBytes) +
           " bytes waited for it (" + (client ? client_ : car_) + ")");
    }
    log_(id_ + " " + format_ms(at) + " closed: " + close.reason + " (" + std::to_string(to_car_) +
         " bytes to the car, " + std::to_string(to_client_) + " to the client)");
  }

 private:
  std::string client_;
  std::string car_;
  std::uint64_t to_car_ = 0;
  std::uint64_t to_client_ = 0;
  std::string id_;
  std::function<void(const std::string&)> log_;
};

// What every link of a proxy adds to: its totals and its recent frames.
struct Tally {
  ProxyCounters totals;
  std::deque<RecentFrame> recent;
  std::size_t keep = 0;  // frames kept in `recent`
};

// Counts what a link delivers: bytes, the frames the route's protocol cuts
// from them (valid or not) and faults, for one link and for the proxy's
// totals, and keeps the newest frames.
class CountingObserver final : public LinkObserver {
 public:
  /// `closed` runs when the link closes (inside the link's own callback).
  CountingObserver(std::shared_ptr<ProxyLinkInfo> info, std::shared_ptr<Tally> tally,
                   std::shared_ptr<const ProtocolAdapter> protocol, std::function<void()> closed)
      : info_(std::move(info)),
        tally_(std::move(tally)),
        protocol_(std::move(protocol)),
        closed_(std::move(closed)) {}

  void on_delivered(Time at, Direction d, protocol::ByteView bytes) override {
    tally_->totals.bytes[slot_of(d)] += bytes.size();
    // Made on a direction's first bytes: a link that carries nothing (a
    // port scan, a client that connects and leaves) costs no decoder.
    auto& splitter = splitters_[slot_of(d)];
    if (!splitter) splitter = protocol_->splitter_for(d, tally_->keep > 0);
    splitter->feed(bytes, frames_);
    count(at, d);
  }
  void on_fault(const FaultEvent& e) override {
    const auto k = static_cast<std::size_t>(e.kind);
    ++info_->faults[k];
    ++tally_->totals.faults[k];
  }
  void on_close(Time at, const LinkClose& close) override {
    // What a side sent last and no frame completed is one bad frame.
    for (const auto d : kProxyDirections) {
      if (!splitters_[slot_of(d)]) continue;
      splitters_[slot_of(d)]->finish(frames_);
      splitters_[slot_of(d)].reset();
      count(at, d);
    }
    info_->open = false;
    info_->close_reason = close.reason;
    if (closed_) closed_();
  }

 private:
  void count(Time at, Direction d) {
    for (auto& frame : frames_) {
      auto& counter = frame.valid ? info_->frames : info_->bad_frames;
      auto& total = frame.valid ? tally_->totals.frames : tally_->totals.bad_frames;
      ++counter[slot_of(d)];
      ++total[slot_of(d)];
      if (tally_->keep == 0) continue;
      frame.text = masked_frame_text(frame.kind, std::move(frame.text));
      tally_->recent.push_back(RecentFrame{info_->number, at, d, std::move(frame)});
      while (tally_->recent.size() > tally_->keep)
        tally_->recent.pop_front();
    }
    frames_.clear();
  }

  std::shared_ptr<ProxyLinkInfo> info_;
  std::shared_ptr<Tally> tally_;
  std::shared_ptr<const ProtocolAdapter> protocol_;
  std::function<void()> closed_;
  std::unique_ptr<FrameSplitter> splitters_[2];
  std::vector<WireFrame> frames_;
};

std::string numbered_path(const std::string& path, std::size_t number) {
  if (number == 1) return path;
  const std::filesystem::path p(path);
  return (p.parent_path() /
          (p.stem().string() + "-" + std::to_string(number) + p.extension().string()))
      .string();
}

// The endpoint to listen on again: the one first asked for, with the port
// the system chose when it asked for port 0 (read from the listener's
// address, "tcp://127.0.0.1:PORT" or "rfc2217://127.0.0.1:PORT?...").
Endpoint as_bound(Endpoint asked, const std::string& address) {
  std::uint16_t* port = nullptr;
  if (auto* tcp = std::get_if<TcpEndpoint>(&asked)) port = &tcp->port;
  if (auto* served = std::get_if<Rfc2217Endpoint>(&asked)) port = &served->port;
  if (port == nullptr || *port != 0) return asked;
  const std::string authority = address.substr(0, address.find('?'));
  const std::size_t colon = authority.rfind(':');
  if (colon == std::string::npos) return asked;
  try {
    *port = static_cast<std::uint16_t>(std::stoul(authority.substr(colon + 1)));
  } catch (const std::exception&) {
    // An address of another form: listen on a free port again.
  }
  return asked;
}

}  // namespace

struct Proxy::LinkRecord {
  std::shared_ptr<ProxyLinkInfo> info = std::make_shared<ProxyLinkInfo>();
  std::shared_ptr<Link> link;
  std::vector<FaultRule> stalls;  // stall_link()'s rules, for this link only
};

struct Proxy::Book : Tally {};

Proxy::Proxy(TransportContext& context, ProxyOptions options)
    : context_(context), options_(std::move(options)), book_(std::make_shared<Book>()) {
  if (!options_.protocol) options_.protocol = protocol_adapter("raw");
  if (options_.name.empty()) options_.name = "proxy";
  book_->keep = options_.recent_frames;
  gate_ = std::make_unique<FaultInjector>(Direction::to_car, options_.protocol,
                                          for_direction(options_.faults, Direction::to_car),
                                          options_.seed);
}

Proxy::~Proxy() {
  *alive_ = false;
  close();
}

void Proxy::say(const std::string& line) const {
  if (options_.log) options_.log(line);
}

void Proxy::start() {
  if (!enabled_ || closed_) return;
  listen_again();
}

void Proxy::listen_again() {
  auto listener = listen(context_, bound_ ? *bound_ : options_.listen);
  if (!bound_) bound_ = as_bound(options_.listen, listener->address());
  std::weak_ptr<bool> alive = alive_;
  listener->start([this, alive](BytePipePtr client) {
    if (const auto a = alive.lock(); a && *a) on_accept(std::move(client));
  });
  listener_ = std::move(listener);
}

std::string Proxy::address() const {
  if (listener_) return listener_->address();
  return to_uri(bound_ ? *bound_ : options_.listen);
}

void Proxy::on_accept(BytePipePtr client) {
  if (!accepting()) {
    client->close(CloseMode::reset);
    return;
  }
  prune();
  const std::size_t number = ++accepted_;
  const std::string id = options_.link_id_prefix + "link" + std::to_string(number);
  if (gate_->refuse_connection(context_.executor.now())) {
    ++refused_;
    say(id + " refused (fault rule): " + client->describe());
    client->close(CloseMode::reset);
    return;
  }
  say(id + " client connected: " + client->describe());
  std::weak_ptr<bool> alive = alive_;
  connect(context_, options_.upstream,
          [this, alive, client, number, id](std::error_code ec, BytePipePtr car) {
            if (const auto a = alive.lock(); !a || !*a) return;
            if (ec || !accepting()) {
              say(id + " cannot reach the car at " + to_uri(options_.upstream) + ": " +
                  (ec ? ec.message() : std::string(closed_ ? "proxy closing" : "proxy disabled")));
              client->close(CloseMode::reset);
              if (car) car->close(CloseMode::reset);
              return;
            }
            join(client, car, number);
          });
}

void Proxy::add_captures(LinkOptions& link_options, const std::string& id,
                         std::size_t number) const {
  std::error_code ec;
  if (!options_.wire_log_path.empty()) {
    auto log = WireLog::open(options_.wire_log_path, WireLogOptions{id, options_.protocol, {}}, ec);
    if (log)
      link_options.observers.push_back(log);
    else
      say(id + " cannot write the wire log " + options_.wire_log_path + ": " + ec.message());
  }
  std::vector<std::string> pcaps;
  if (!options_.pcap_path.empty()) pcaps.push_back(numbered_path(options_.pcap_path, number));
  if (!options_.pcap_dir.empty()) {
    pcaps.push_back((std::filesystem::path(options_.pcap_dir) /
                     (options_.name + "-link" + std::to_string(number) + ".pcap"))
                        .string());
  }
  for (const auto& path : pcaps) {
    auto pcap = PcapWriter::open(path, PcapOptions{}, ec);
    if (pcap)
      link_options.observers.push_back(pcap);
    else
      say(id + " cannot write the pcap " + path + ": " + ec.message());
  }
}

void Proxy::join(BytePipePtr client, BytePipePtr car, std::size_t number) {
  const std::string id = options_.link_id_prefix + "link" + std::to_string(number);
  // A side that never reads must not grow the proxy without end.
  client->set_send_limit(kMaxSendBacklogBytes);
  car->set_send_limit(kMaxSendBacklogBytes);
  auto record = std::make_shared<LinkRecord>();
  ProxyLinkInfo& info = *record->info;
  info.number = number;
  info.seed = options_.seed + number - 1;
  info.client = client->describe();
  info.car = car->describe();
  info.opened_at = context_.executor.now();
  info.open = true;

  LinkOptions link_options;
  link_options.protocol = options_.protocol;
  link_options.set_faults(rules_for(*record));
  link_options.seed = info.seed;
  // A closed link's pipes and injectors are let go soon after it closes,
  // not at the next connection: a storm of clients that all leave at once
  // costs nothing once they have gone.
  std::weak_ptr<bool> alive = alive_;
  auto closed = [this, alive] {
    if (prune_posted_) return;
    prune_posted_ = true;
    context_.executor.post([this, alive] {
      if (const auto a = alive.lock(); !a || !*a) return;
      prune_posted_ = false;
      prune();
    });
  };
  link_options.observers.push_back(
      std::make_shared<CountingObserver>(record->info, book_, options_.protocol, closed));
  if (options_.log)
    link_options.observers.push_back(std::make_shared<TerminalObserver>(id, options_.log));
  add_captures(link_options, id, number);
  record->link =
      Link::create(context_.executor, std::move(client), std::move(car), std::move(link_options));
  records_.push_back(record);
  ++links_opened_;
  say(id + " joined to the car at " + to_uri(options_.upstream) + " (seed " +
      std::to_string(info.seed) + ")");
  record->link->start(info.opened_at);
}

FaultProfile Proxy::rules_for(const LinkRecord& record) const {
  FaultProfile rules = options_.faults;
  if (options_.link_faults) {
    auto more = options_.link_faults(*record.info);
    rules.rules.insert(rules.rules.end(), std::make_move_iterator(more.rules.begin()),
                       std::make_move_iterator(more.rules.end()));
  }
  rules.rules.insert(rules.rules.end(), record.stalls.begin(), record.stalls.end());
  return rules;
}

void Proxy::close() {
  if (closed_) return;
  closed_ = true;
  if (listener_) listener_->close();
  for (auto& record : records_) {
    if (record->link) record->link->close();
  }
}

void Proxy::set_faults(const FaultProfile& faults) {
  options_.faults = faults;
  gate_->set_profile(for_direction(faults, Direction::to_car));
  refresh_faults();
}

void Proxy::refresh_faults() {
  for (auto& record : records_) {
    if (record->link && record->link->is_open()) record->link->set_faults(rules_for(*record));
  }
}

void Proxy::set_enabled(bool enabled) {
  if (enabled == enabled_ || closed_) return;
  if (!enabled) {
    enabled_ = false;
    if (listener_) listener_->close();
    listener_.reset();
    // Toxiproxy's cut: every client and the car see their connection end at once.
    for (auto& record : records_) {
      if (record->link && record->link->is_open()) record->link->close(CloseMode::reset);
    }
    say(options_.name + " disabled: not listening, every link closed");
    return;
  }
  listen_again();
  enabled_ = true;
  say(options_.name + " enabled: clients connect to " + address());
}

bool Proxy::enabled() const {
  return enabled_ && !closed_;
}

Proxy::LinkRecord* Proxy::open_record(std::size_t number) {
  for (auto& record : records_) {
    if (record->info->number == number && record->link && record->link->is_open())
      return record.get();
  }
  return nullptr;
}

bool Proxy::stall_link(std::size_t number, Duration duration, DirectionFilter which) {
  LinkRecord* record = open_record(number);
  if (record == nullptr) return false;
  const Time now = context_.executor.now();
  // Stalls that have ended are done with: only the new one is added.
  std::erase_if(record->stalls, [&](const FaultRule& rule) {
    return *rule.trigger.at + std::get<Stall>(rule.action).duration < now;
  });
  FaultRule rule;
  rule.name = "stall_link";
  rule.direction = which;
  rule.trigger.at = now;
  rule.action = Stall{duration};
  record->stalls.push_back(std::move(rule));
  record->link->set_faults(rules_for(*record));
  say(options_.link_id_prefix + "link" + std::to_string(number) + " stalled for " +
      format_ms(duration) + " (" + std::string(to_string(which)) + ")");
  return true;
}

bool Proxy::reset_link(std::size_t number) {
  LinkRecord* record = open_record(number);
  if (record == nullptr) return false;
  record->link->close(CloseMode::reset);
  return true;
}

void Proxy::prune() {
  // A closed link is kept as its figures only: its pipes, injectors and
  // observers go at once, and the oldest figures beyond closed_links_kept.
  std::size_t closed_seen = 0;
  for (auto it = records_.rbegin(); it != records_.rend(); ++it) {
    auto& record = **it;
    if (record.info->open) continue;
    if (record.link) {
      record.info->stats = record.link->stats();
      record.link.reset();
      record.stalls.clear();
    }
    if (++closed_seen > options_.closed_links_kept) record.info.reset();
  }
  std::erase_if(records_, [](const auto& record) { return record->info == nullptr; });
}

std::vector<ProxyLinkInfo> Proxy::links() const {
  std::vector<ProxyLinkInfo> open;
  std::vector<ProxyLinkInfo> closed;
  for (const auto& record : records_) {
    ProxyLinkInfo info = *record->info;
    if (record->link) info.stats = record->link->stats();
    (info.open ? open : closed).push_back(std::move(info));
  }
  if (closed.size() > options_.closed_links_kept)
    closed.erase(closed.begin(),
                 closed.end() - static_cast<std::ptrdiff_t>(options_.closed_links_kept));
  open.insert(open.end(), std::make_move_iterator(closed.begin()),
              std::make_move_iterator(closed.end()));
  return open;
}

std::vector<RecentFrame> Proxy::recent_frames(std::size_t limit) const {
  const auto& recent = book_->recent;
  const std::size_t n = std::min(limit, recent.size());
  return {recent.end() - static_cast<std::ptrdiff_t>(n), recent.end()};
}

ProxyCounters Proxy::counters() const {
  ProxyCounters c = book_->totals;
  c.connections = accepted_;
  c.refused = refused_;
  c.links_opened = links_opened_;
  c.open_links = open_links();
  return c;
}

std::size_t Proxy::open_links() const {
  return static_cast<std::size_t>(
      std::count_if(records_.begin(), records_.end(),
                    [](const auto& record) { return record->link && record->link->is_open(); }));
}

}  // namespace hil::link
