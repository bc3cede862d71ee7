#include "link/capture/probe_capture.hpp"

#include "base/enum_names.hpp"

#include <cmath>
#include <utility>

#include "link/time.hpp"

namespace hil::link {

namespace {

constexpr auto kExchangeKindNames = base::enum_names<ExchangeKind>(
    {ExchangeKind::command, "command"}, {ExchangeKind::boundary, "boundary"},
    {ExchangeKind::error, "error"}, {ExchangeKind::framing, "framing"},
    {ExchangeKind::telemetry, "telemetry"}, {ExchangeKind::connect, "connect"},
    {ExchangeKind::stop, "stop"});

// The wire log writes times to the microsecond; the recorder keeps them so,
// so a capture read back equals the one recorded.
Time to_us_precision(Time at) {
  return std::chrono::microseconds(std::llround(static_cast<double>(at.count()) / 1000.0));
}

Time time_of(const nlohmann::json& record) {
  return std::chrono::microseconds(std::llround(record.at("t_ms").get<double>() * 1000.0));
}

std::optional<LinkClose::By> parse_by(std::string_view text) {
  for (const auto by :
       {LinkClose::By::client, LinkClose::By::car, LinkClose::By::fault, LinkClose::By::hil}) {
    if (to_string(by) == text) return by;
  }
  return std::nullopt;
}

}  // namespace

std::string_view to_string(ExchangeKind kind) {
  return kExchangeKindNames.name(kind);
}

std::optional<ExchangeKind> parse_exchange_kind(std::string_view text) {
  return kExchangeKindNames.parse(text);
}

CaptureRecorder::CaptureRecorder(CaptureHeader header, std::shared_ptr<WireLog> log)
    : log_(std::move(log)) {
  capture_.header = std::move(header);
  if (log_) {
    const auto& h = capture_.header;
    log_->on_note(Time{0}, "probe",
                  {{"probe", h.probe_version},
                   {"car", h.car},
                   {"profile", h.profile},
                   {"target", h.target},
                   {"started_wall_us", h.started_wall_us}});
  }
}

CapturedExchange* CaptureRecorder::current() {
  return in_exchange_ ? &capture_.exchanges.back() : nullptr;
}

void CaptureRecorder::begin_exchange(Time at, std::string name, ExchangeKind kind,
                                     std::string what) {
  if (in_exchange_) end_exchange(at);
  at = to_us_precision(at);
  capture_.exchanges.push_back({std::move(name), std::move(what), kind, at, at, {}});
  in_exchange_ = true;
  if (log_) {
    const auto& e = capture_.exchanges.back();
    log_->on_note(at, "exchange",
                  {{"index", capture_.exchanges.size() - 1},
                   {"name", e.name},
                   {"kind", std::string(to_string(kind))},
                   {"what", e.what}});
  }
}

void CaptureRecorder::end_exchange(Time at) {
  auto* exchange = current();
  if (!exchange) return;
  exchange->end = to_us_precision(at);
  in_exchange_ = false;
  if (log_)
    log_->on_note(exchange->end, "exchange_end", {{"index", capture_.exchanges.size() - 1}});
}

void CaptureRecorder::opened(Time at, const std::string& client, const std::string& car) {
  at = to_us_precision(at);
  if (auto* exchange = current()) exchange->events.push_back({CaptureEvent::Kind::opened, at, {}});
  if (log_) log_->on_open(at, client, car);
}

void CaptureRecorder::sent(Time at, protocol::ByteView bytes) {
  at = to_us_precision(at);
  if (auto* exchange = current()) {
    exchange->events.push_back({CaptureEvent::Kind::sent, at, Bytes(bytes.begin(), bytes.end())});
  }
  if (log_) log_->on_sent(at, Direction::to_car, bytes);
}

void CaptureRecorder::received(Time at, protocol::ByteView bytes) {
  at = to_us_precision(at);
  if (auto* exchange = current()) {
    exchange->events.push_back(
        {CaptureEvent::Kind::received, at, Bytes(bytes.begin(), bytes.end())});
  }
  if (log_) log_->on_delivered(at, Direction::to_client, bytes);
}

void CaptureRecorder::closed(Time at, const LinkClose& close) {
  at = to_us_precision(at);
  if (auto* exchange = current())
    exchange->events.push_back({CaptureEvent::Kind::closed, at, {}, close.by});
  if (log_) log_->on_close(at, close);
}

std::shared_ptr<WireLog> open_capture_log(const std::filesystem::path& path,
                                          std::shared_ptr<const ProtocolAdapter> protocol) {
  std::error_code ec;
  WireLogOptions options;
  options.link_id = "probe";
  options.protocol = std::move(protocol);
  options.mode = CaptureFile::Mode::truncate;
  auto log = WireLog::open(path, std::move(options), ec);
  if (!log) throw CaptureError("cannot write the capture " + path.string() + ": " + ec.message());
  return log;
}

namespace {

// Reads one record into `capture`; `line` is for the messages.
class CaptureReader {
 public:
  explicit CaptureReader(std::string file) : file_(std::move(file)) {}

  void read(const nlohmann::json& record, std::size_t line) {
    line_ = line;
    if (!record.is_object() || !record.contains("event") || !record["event"].is_string())
      fail("a record without an \"event\"");
    const auto event = record["event"].get<std::string>();
    if (!header_seen_) {
      if (event != "probe") {
        fail("not a probe capture: its first record is \"" + event +
             "\", not \"probe\" (hil conform probe writes captures)");
      }
      read_header(record);
      return;
    }
    if (event == "exchange") {
      capture_.exchanges.push_back({string_of(record, "name"),
                                    string_of(record, "what"),
                                    kind_of(record),
                                    time_of(record),
                                    time_of(record),
                                    {}});
      in_exchange_ = true;
      return;
    }
    if (event == "exchange_end") {
      if (!in_exchange_) fail("an \"exchange_end\" record with no exchange open");
      exchange().end = time_of(record);
      in_exchange_ = false;
      return;
    }
    // The probe's own close after its last exchange belongs to none.
    if (!in_exchange_) return;
    if (event == "open") {
      exchange().events.push_back({CaptureEvent::Kind::opened, time_of(record), {}});
    } else if (event == "sent" && string_of(record, "dir") == "to_car") {
      exchange().events.push_back({CaptureEvent::Kind::sent, time_of(record), bytes_of(record)});
    } else if (event == "delivered" && string_of(record, "dir") == "to_client") {
      exchange().events.push_back(
          {CaptureEvent::Kind::received, time_of(record), bytes_of(record)});
    } else if (event == "close") {
      const auto by = parse_by(string_of(record, "by"));
      if (!by) fail("a close record whose \"by\" is not client, car, fault or hil");
      exchange().events.push_back({CaptureEvent::Kind::closed, time_of(record), {}, *by});
    }
  }

  Capture finish() {
    if (!header_seen_) throw CaptureError(file_ + ": empty: no probe record");
    return std::move(capture_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw CaptureError(file_ + ":" + std::to_string(line_) + ": " + what);
  }

  std::string string_of(const nlohmann::json& record, const char* key) const {
    if (!record.contains(key) || !record[key].is_string())
      fail(std::string("a \"") + record.value("event", "") + "\" record without a string \"" + key +
           "\"");
    return record[key].get<std::string>();
  }

  ExchangeKind kind_of(const nlohmann::json& record) const {
    const auto text = string_of(record, "kind");
    const auto kind = parse_exchange_kind(text);
    if (!kind) fail("an exchange of unknown kind \"" + text + "\"");
    return *kind;
  }

  CapturedExchange& exchange() { return capture_.exchanges.back(); }

  void read_header(const nlohmann::json& record) {
    auto& h = capture_.header;
    h.probe_version = string_of(record, "probe");
    h.car = string_of(record, "car");
    h.profile = string_of(record, "profile");
    h.target = string_of(record, "target");
    h.started_wall_us = record.value("started_wall_us", std::int64_t{0});
    header_seen_ = true;
  }

  std::string file_;
  std::size_t line_ = 0;
  bool header_seen_ = false;
  bool in_exchange_ = false;
  Capture capture_;
};

}  // namespace

Capture read_capture(const std::filesystem::path& path) {
  std::vector<nlohmann::json> records;
  try {
    records = read_wire_log(path);
  } catch (const std::exception& e) {
    throw CaptureError(e.what());
  }
  CaptureReader reader(path.string());
  for (std::size_t i = 0; i < records.size(); ++i) {
    try {
      reader.read(records[i], i + 1);
    } catch (const nlohmann::json::exception& e) {
      throw CaptureError(path.string() + ":" + std::to_string(i + 1) + ": " + e.what());
    }
  }
  return reader.finish();
}

}  // namespace hil::link
