#pragma once
// The fault-injecting proxy: listens where a client expects its car, and
// joins each client to a new connection to the real car (or a mock) through
// a Link with faults and capture. `hil proxy` is a thin main around it.

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "link/endpoint.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "link/transport.hpp"

namespace hil::link {

/// One link of a proxy, as the control API lists it.
struct ProxyLinkInfo {
  std::size_t number = 0;  ///< 1, 2, ... in the order clients connected ("link<N>")
  std::uint64_t seed = 0;  ///< its fault seed (the proxy's seed + number - 1)
  std::string client;      ///< the client pipe's description
  std::string car;         ///< the car pipe's description
  Time opened_at{0};
  bool open = false;
  std::string close_reason;                             ///< empty while open
  LinkStats stats;                                      ///< bytes sent and delivered, by direction
  std::array<std::uint64_t, 2> frames{};                ///< frames decoded, by Direction
  std::array<std::uint64_t, 2> bad_frames{};            ///< undecodable runs, by Direction
  std::array<std::uint64_t, kFaultKindCount> faults{};  ///< by FaultKind
};

/// A frame the route's protocol decoded on one of its links.
struct RecentFrame {
  std::size_t link = 0;
  Time at{0};
  Direction direction = Direction::to_car;
  WireFrame frame;
};

/// A proxy's totals over every link it served, closed ones included.
struct ProxyCounters {
  std::uint64_t connections = 0;  ///< clients accepted (refused ones included)
  /// Refused by a refuse rule. A disabled proxy does not listen at all
  /// (Toxiproxy's way): the system turns its clients away, uncounted.
  std::uint64_t refused = 0;
  std::uint64_t links_opened = 0;
  std::uint64_t open_links = 0;
  std::array<std::uint64_t, 2> bytes{};                 ///< delivered, by Direction
  std::array<std::uint64_t, 2> frames{};                ///< decoded, by Direction
  std::array<std::uint64_t, 2> bad_frames{};            ///< by Direction
  std::array<std::uint64_t, kFaultKindCount> faults{};  ///< by FaultKind
};

struct ProxyOptions {
  /// The route's name in logs and the control API; "proxy" when empty.
  std::string name;
  Endpoint listen;    ///< where clients connect (tcp:// or pty://)
  Endpoint upstream;  ///< the car: tcp://, pty:// (a device path) or mem://
  std::shared_ptr<const ProtocolAdapter> protocol;  ///< null: raw
  FaultProfile faults;  ///< rules for both directions (each rule's direction filter applies)
  /// Rules a link gets on top of `faults`, asked for when it opens and on
  /// refresh_faults() (Toxiproxy's toxics, drawn per link); may be empty.
  std::function<FaultProfile(const ProxyLinkInfo& link)> link_faults;
  std::uint64_t seed = 0;  ///< link N uses seed + N - 1, so links differ and replay
  /// NDJSON wire log shared by every link (records carry "link": "link<N>"); empty: none.
  std::string wire_log_path;
  /// pcap of the first link; link N > 1 writes "<stem>-<N><ext>"; empty: none.
  std::string pcap_path;
  /// A folder for one pcap per link, "<dir>/<name>-link<N>.pcap"; empty: none.
  std::string pcap_dir;
  /// Put before "link<N>" in the wire log's "link" field and in log lines,
  /// so several proxies can share one file ("car/" gives "car/link1").
  std::string link_id_prefix;
  /// One line per event for the terminal (connections, faults, errors); may be empty.
  std::function<void(const std::string&)> log;
  /// Decoded frames kept for recent_frames(), across the route's links.
  std::size_t recent_frames = 256;
  /// Closed links still listed by links() (the newest ones).
  std::size_t closed_links_kept = 32;
};

class Proxy {
 public:
  /// `context` must outlive the proxy.
  Proxy(TransportContext& context, ProxyOptions options);
  ~Proxy();
  Proxy(const Proxy&) = delete;
  Proxy& operator=(const Proxy&) = delete;

  /// Starts listening. Throws (EndpointError, std::system_error, or
  /// std::runtime_error for a capture file that cannot be opened).
  void start();
  /// Stops listening and closes every link.
  void close();
  /// Where clients connect (the listener's URI, with the real port).
  std::string address() const;
  /// The endpoint it listens on: as asked, with the real port once bound
  /// (a tcp:// port 0 keeps the port it first got, disabled or not).
  Endpoint listening_on() const { return bound_ ? *bound_ : options_.listen; }

  /// Replaces the fault rules of every open link and of links to come.
  void set_faults(const FaultProfile& faults);
  const FaultProfile& faults() const { return options_.faults; }
  /// Asks options.link_faults again for every open link (a toxic changed).
  void refresh_faults();

  /// Toxiproxy's enabled flag: disabling stops listening and closes every
  /// link; enabling listens again on the same address. Throws as start().
  void set_enabled(bool enabled);
  bool enabled() const;

  /// Delivers nothing on link `number` for `duration` from now, in the
  /// directions `which` names; false when no such link is open.
  bool stall_link(std::size_t number, Duration duration, DirectionFilter which);
  /// Resets link `number` (TCP RST to both sides) now; false when no such link is open.
  bool reset_link(std::size_t number);

  /// The open links, then the newest closed ones, in the order they opened.
  std::vector<ProxyLinkInfo> links() const;
  /// The last `limit` frames decoded on any link, oldest first.
  std::vector<RecentFrame> recent_frames(std::size_t limit) const;
  ProxyCounters counters() const;
  const ProxyOptions& options() const { return options_; }

  std::size_t links_opened() const { return links_opened_; }
  std::size_t connections_refused() const { return refused_; }
  std::size_t open_links() const;

 private:
  /// One link and what is counted on it; shared with its observer.
  struct LinkRecord;
  bool prune_posted_ = false;  // a prune() is scheduled (a link closed)
  /// The totals and the recent frames; shared with every link's observer.
  struct Book;

  void listen_again();
  bool accepting() const { return !closed_ && enabled_; }
  void on_accept(BytePipePtr client);
  void join(BytePipePtr client, BytePipePtr car, std::size_t number);
  void add_captures(LinkOptions& link_options, const std::string& id, std::size_t number) const;
  /// options.faults, then link_faults(link), then the link's own stalls.
  FaultProfile rules_for(const LinkRecord& record) const;
  LinkRecord* open_record(std::size_t number);
  /// Keeps closed links as their figures only, and forgets the oldest
  /// beyond options.closed_links_kept.
  void prune();
  void say(const std::string& line) const;

  TransportContext& context_;
  ProxyOptions options_;
  std::unique_ptr<Listener> listener_;
  std::optional<Endpoint> bound_;        // the listen address as first bound (its real port)
  std::unique_ptr<FaultInjector> gate_;  // answers refuse_connection()
  std::vector<std::shared_ptr<LinkRecord>> records_;  // in the order the links opened
  std::shared_ptr<Book> book_;
  std::size_t links_opened_ = 0;
  std::size_t accepted_ = 0;
  std::size_t refused_ = 0;
  bool closed_ = false;
  bool enabled_ = true;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::link
