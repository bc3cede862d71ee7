#include "link/capture/wire_log.hpp"

#include <fstream>
#include <stdexcept>
#include <utility>

namespace hil::link {

namespace {

constexpr std::size_t kSent = 0;
constexpr std::size_t kDelivered = 1;
constexpr const char* kStageNames[2] = {"sent", "delivered"};

std::size_t index_of(Direction d) {
  return static_cast<std::size_t>(d);
}

// Milliseconds rounded to whole microseconds, so a log never shows float
// noise below the precision it promises.
double ms_with_us_precision(Time at) {
  const auto us = std::chrono::round<std::chrono::microseconds>(at).count();
  return static_cast<double>(us) / 1000.0;
}

bool is_text_byte(std::uint8_t b) {
  return (b >= 0x20 && b <= 0x7E) || b == '\t' || b == '\r' || b == '\n';
}

nlohmann::ordered_json frames_json(const std::vector<WireFrame>& frames) {
  auto list = nlohmann::ordered_json::array();
  for (const auto& f : frames) {
    list.push_back(
        {{"kind", f.kind}, {"valid", f.valid}, {"text", masked_frame_text(f.kind, f.text)}});
  }
  return list;
}

template <class Json>
void put_bytes_into(Json& record, protocol::ByteView bytes) {
  record["bytes"] = bytes.size();
  bool text = true;
  for (auto b : bytes) {
    if (!is_text_byte(b)) {
      text = false;
      break;
    }
  }
  if (text) {
    record["text"] = protocol::to_string(bytes);
  } else {
    record["hex"] = protocol::to_hex(bytes);
  }
}

}  // namespace

std::string masked_frame_text(std::string_view kind, std::string text) {
  if (kind != "AUTH" || text.empty()) return text;
  // Already masked (a log read back and written again): as it is.
  if (text.find("text=**********") != std::string::npos &&
      text.find("text=\"") == std::string::npos)
    return text;
  // 'Auth text="..." (profile string)': keep the verdict, hide the string.
  const auto open = text.find("text=\"");
  const auto close = text.rfind('"');
  if (open == std::string::npos || close <= open + 5) return "Auth text=**********";
  return text.substr(0, open) + "text=**********" + text.substr(close + 1);
}

void put_bytes(nlohmann::json& record, protocol::ByteView bytes) {
  put_bytes_into(record, bytes);
}
void put_bytes(nlohmann::ordered_json& record, protocol::ByteView bytes) {
  put_bytes_into(record, bytes);
}

protocol::Bytes bytes_of(const nlohmann::json& record) {
  if (auto it = record.find("text"); it != record.end() && it->is_string()) {
    return protocol::to_bytes(it->get<std::string>());
  }
  if (auto it = record.find("hex"); it != record.end() && it->is_string()) {
    return protocol::parse_hex(it->get<std::string>()).value_or(protocol::Bytes{});
  }
  return {};
}

std::shared_ptr<WireLog> WireLog::open(const std::filesystem::path& path, WireLogOptions options,
                                       std::error_code& ec) {
  auto file = CaptureFile::open(path, options.mode, ec);
  if (!file) return nullptr;
  return std::shared_ptr<WireLog>(new WireLog(path, std::move(*file), std::move(options)));
}

WireLog::WireLog(std::filesystem::path path, CaptureFile file, WireLogOptions options)
    : path_(std::move(path)), file_(std::move(file)), options_(std::move(options)) {
  if (!options_.wall_clock_us) options_.wall_clock_us = [] { return wall_time_us(); };
  if (options_.protocol) {
    for (auto& kind : splitters_) {
      for (const auto d : {Direction::to_car, Direction::to_client})
        kind[index_of(d)] = options_.protocol->splitter_for(d);
    }
  }
}

WireLog::~WireLog() = default;

nlohmann::ordered_json WireLog::record(const char* event, Time at) const {
  nlohmann::ordered_json r;
  r["link"] = options_.link_id;
  r["event"] = event;
  r["t_ms"] = ms_with_us_precision(at);
  r["wall_us"] = options_.wall_clock_us();
  return r;
}

void WireLog::on_open(Time at, const std::string& client, const std::string& car) {
  auto r = record("open", at);
  r["client"] = client;
  r["car"] = car;
  r["protocol"] = options_.protocol ? std::string(options_.protocol->name()) : std::string("raw");
  if (options_.protocol && !options_.protocol->profile().empty()) {
    r["profile"] = std::string(options_.protocol->profile());
  }
  write_line(r);
}

void WireLog::on_sent(Time at, Direction d, protocol::ByteView bytes) {
  on_bytes(kStageNames[kSent], kSent, at, d, bytes);
}

void WireLog::on_delivered(Time at, Direction d, protocol::ByteView bytes) {
  on_bytes(kStageNames[kDelivered], kDelivered, at, d, bytes);
}

void WireLog::on_bytes(const char* event, std::size_t kind_index, Time at, Direction d,
                       protocol::ByteView bytes) {
  auto r = record(event, at);
  r["dir"] = std::string(to_string(d));
  put_bytes(r, bytes);
  if (auto& splitter = splitters_[kind_index][index_of(d)]) {
    std::vector<WireFrame> frames;
    splitter->feed(bytes, frames);
    r["frames"] = frames_json(frames);
    r["held"] = splitter->buffered();
  }
  write_line(r);
}

void WireLog::on_fault(const FaultEvent& event) {
  auto r = record("fault", event.at);
  r["dir"] = std::string(to_string(event.direction));
  r["kind"] = to_string(event.kind);
  r["rule"] = event.rule;
  r["detail"] = event.detail;
  nlohmann::ordered_json before;
  nlohmann::ordered_json after;
  put_bytes(before, event.before);
  put_bytes(after, event.after);
  r["before"] = std::move(before);
  r["after"] = std::move(after);
  write_line(r);
}

void WireLog::on_close(Time at, const LinkClose& close) {
  auto r = record("close", at);
  r["by"] = std::string(to_string(close.by));
  r["mode"] = close.mode == CloseMode::reset ? "reset" : "graceful";
  r["reason"] = close.reason;
  // A partial frame still held at close is the last thing a reader of the
  // log wants to miss ("the car cut the STAT frame in half"): list it.
  auto leftovers = unfinished({Direction::to_car, Direction::to_client});
  if (!leftovers.empty()) r["unfinished"] = std::move(leftovers);
  write_line(r);
}

void WireLog::on_half_close(Time at, Direction d) {
  auto r = record("half_close", at);
  r["dir"] = std::string(to_string(d));
  r["by"] = d == Direction::to_car ? "client" : "car";
  // Nothing more comes in this direction: a partial frame is final now.
  auto leftovers = unfinished({d});
  if (!leftovers.empty()) r["unfinished"] = std::move(leftovers);
  write_line(r);
}

nlohmann::ordered_json WireLog::unfinished(std::initializer_list<Direction> dirs) {
  auto leftovers = nlohmann::ordered_json::array();
  for (std::size_t kind = 0; kind < 2; ++kind) {
    for (const auto d : dirs) {
      auto& splitter = splitters_[kind][index_of(d)];
      if (!splitter) continue;
      std::vector<WireFrame> frames;
      splitter->finish(frames);
      if (frames.empty()) continue;
      leftovers.push_back({{"event", kStageNames[kind]},
                           {"dir", std::string(to_string(d))},
                           {"frames", frames_json(frames)}});
    }
  }
  return leftovers;
}

void WireLog::on_note(Time at, const char* event, const nlohmann::ordered_json& fields) {
  auto r = record(event, at);
  for (const auto& [key, value] : fields.items())
    r[key] = value;
  write_line(r);
}

void WireLog::write_line(const nlohmann::ordered_json& record) {
  // Invalid UTF-8 cannot reach here (text is ASCII only, the rest is hex),
  // but frame texts come from decoders: replace rather than throw.
  std::string line = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  line.push_back('\n');
  // One write per line on a file opened to append: the kernel puts the
  // whole line at the end of the file even when other links log to it.
  if (file_.write(
          protocol::ByteView(reinterpret_cast<const std::uint8_t*>(line.data()), line.size())))
    ++records_written_;
}

std::shared_ptr<const ProtocolAdapter> adapter_of_log(const nlohmann::json& open_record) {
  const auto text_field = [&](const char* name) -> std::string {
    const auto it = open_record.find(name);
    return it != open_record.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  if (text_field("event") != "open") {
    throw std::invalid_argument("a wire log names its protocol in its \"open\" record, not in \"" +
                                text_field("event") + "\"");
  }
  const std::string protocol = text_field("protocol");
  if (protocol.empty()) throw std::invalid_argument("the wire log's open record has no protocol");
  return protocol_adapter(protocol, text_field("profile"));
}

std::vector<nlohmann::json> read_wire_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open the wire log");
  std::vector<nlohmann::json> records;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const bool complete = !in.eof();  // getline stopped at a newline
    if (line.empty()) continue;
    auto parsed = nlohmann::json::parse(line, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object()) {
      if (!complete) break;
      throw std::runtime_error(path.string() + ":" + std::to_string(line_no) +
                               ": expected one JSON object per line");
    }
    records.push_back(std::move(parsed));
  }
  return records;
}

}  // namespace hil::link
