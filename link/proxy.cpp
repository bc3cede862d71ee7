#include "link/proxy.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "link/capture/pcap.hpp"
#include "link/capture/wire_log.hpp"

namespace hil::link {
namespace {

// Prints connections and faults as they happen.
class TerminalObserver final : public LinkObserver {
 public:
  TerminalObserver(std::string id, std::function<void(const std::string&)> log)
      : id_(std::move(id)), log_(std::move(log)) {}
  void on_fault(const FaultEvent& e) override {
    log_(id_ + " " + format_ms(e.at) + " fault " + std::string(to_string(e.kind)) + " (" + e.rule + ", " +
         std::string(to_string(e.direction)) + "): " + e.detail);
  }
  void on_sent(Time /*at*/, Direction d, protocol::ByteView bytes) override {
    (d == Direction::to_car ? to_car_ : to_client_) += bytes.size();
  }
  void on_open(Time /*at*/, const std::string& client, const std::string& car) override {
    client_ = client;
    car_ = car;
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

std::string numbered_path(const std::string& path, std::size_t number) {
  if (number == 1) return path;
  const std::filesystem::path p(path);
  return (p.parent_path() /
          (p.stem().string() + "-" + std::to_string(number) + p.extension().string()))
      .string();
}

}  // namespace

Proxy::Proxy(TransportContext& context, ProxyOptions options)
    : context_(context), options_(std::move(options)) {
  if (!options_.protocol) options_.protocol = protocol_adapter("raw");
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
  listener_ = listen(context_, options_.listen);
  std::weak_ptr<bool> alive = alive_;
  listener_->start([this, alive](BytePipePtr client) {
    if (alive.lock() && *alive.lock()) on_accept(std::move(client));
  });
}

std::string Proxy::address() const {
  return listener_ ? listener_->address() : to_uri(options_.listen);
}

void Proxy::on_accept(BytePipePtr client) {
  if (closed_) {
    client->close(CloseMode::reset);
    return;
  }
  std::erase_if(links_, [](const std::shared_ptr<Link>& link) { return !link->is_open(); });
  const std::size_t number = ++accepted_;
  if (gate_->refuse_connection(context_.executor.now())) {
    ++refused_;
    say("link" + std::to_string(number) + " refused (fault rule): " + client->describe());
    client->close(CloseMode::reset);
    return;
  }
  say("link" + std::to_string(number) + " client connected: " + client->describe());
  std::weak_ptr<bool> alive = alive_;
  connect(context_, options_.upstream,
          [this, alive, client, number](std::error_code ec, BytePipePtr car) {
            if (!alive.lock() || !*alive.lock()) return;
            if (ec || closed_) {
              say("link" + std::to_string(number) + " cannot reach the car at " +
                  to_uri(options_.upstream) + ": " +
                  (ec ? ec.message() : std::string("proxy closing")));
              client->close(CloseMode::reset);
              if (car) car->close(CloseMode::reset);
              return;
            }
            join(client, car, number);
          });
}

void Proxy::join(BytePipePtr client, BytePipePtr car, std::size_t number) {
  const std::string id = "link" + std::to_string(number);
  // A side that never reads must not grow the proxy without end.
  client->set_send_limit(kMaxSendBacklogBytes);
  car->set_send_limit(kMaxSendBacklogBytes);
  LinkOptions link_options;
  link_options.protocol = options_.protocol;
  link_options.set_faults(options_.faults);
  link_options.seed = options_.seed + number - 1;
  if (options_.log)
    link_options.observers.push_back(std::make_shared<TerminalObserver>(id, options_.log));
  std::error_code ec;
  if (!options_.wire_log_path.empty()) {
    auto log = WireLog::open(options_.wire_log_path, WireLogOptions{id, options_.protocol, {}}, ec);
    if (log)
      link_options.observers.push_back(log);
    else
      say(id + " cannot write the wire log " + options_.wire_log_path + ": " + ec.message());
  }
  if (!options_.pcap_path.empty()) {
    const std::string path = numbered_path(options_.pcap_path, number);
    auto pcap = PcapWriter::open(path, PcapOptions{}, ec);
    if (pcap)
      link_options.observers.push_back(pcap);
    else
      say(id + " cannot write the pcap " + path + ": " + ec.message());
  }
  auto link =
      Link::create(context_.executor, std::move(client), std::move(car), std::move(link_options));
  links_.push_back(link);
  ++links_opened_;
  say(id + " joined to the car at " + to_uri(options_.upstream) + " (seed " +
      std::to_string(options_.seed + number - 1) + ")");
  link->start();
}

void Proxy::close() {
  if (closed_) return;
  closed_ = true;
  if (listener_) listener_->close();
  for (auto& link : links_)
    link->close();
}

void Proxy::set_faults(const FaultProfile& faults) {
  options_.faults = faults;
  gate_->set_profile(for_direction(faults, Direction::to_car));
  for (auto& link : links_) {
    if (link->is_open()) link->set_faults(faults);
  }
}

std::size_t Proxy::open_links() const {
  return static_cast<std::size_t>(std::count_if(links_.begin(), links_.end(),
                                                [](const auto& link) { return link->is_open(); }));
}

}  // namespace hil::link
