#include "link/capture/pcap.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <string_view>
#include <utility>
#include <vector>

#include <asio/ip/address_v4.hpp>

namespace hil::link {

namespace {

constexpr std::uint32_t kMagicNanoseconds = 0xa1b23c4d;
constexpr std::uint32_t kLinktypeRawIpv4 = 101;
constexpr std::uint32_t kSnapLength = 65535;

constexpr std::uint8_t kFin = 0x01;
constexpr std::uint8_t kSyn = 0x02;
constexpr std::uint8_t kRst = 0x04;
constexpr std::uint8_t kPsh = 0x08;
constexpr std::uint8_t kAck = 0x10;

constexpr std::size_t kIpHeaderBytes = 20;
constexpr std::size_t kTcpHeaderBytes = 20;
constexpr std::size_t kMssOptionBytes = 4;

// Fixed initial sequence numbers keep captures of the same run identical
// byte for byte; Wireshark shows relative numbers anyway.
constexpr std::uint32_t kClientIsn = 0x1000'0000;
constexpr std::uint32_t kCarIsn = 0x2000'0000;

void put16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}

void put32(std::uint8_t* p, std::uint32_t v) {
  put16(p, static_cast<std::uint16_t>(v >> 16));
  put16(p + 2, static_cast<std::uint16_t>(v));
}

// Pcap headers are written in the writer's byte order; the magic number
// tells readers which one that was.
template <typename T>
void put_native(std::vector<std::uint8_t>& out, T v) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  out.insert(out.end(), raw, raw + sizeof(T));
}

// The Internet checksum (RFC 1071): ones' complement sum of 16-bit words.
std::uint32_t sum_words(const std::uint8_t* p, std::size_t n, std::uint32_t sum = 0) {
  for (std::size_t i = 0; i + 1 < n; i += 2)
    sum += static_cast<std::uint32_t>(p[i] << 8 | p[i + 1]);
  if (n % 2 != 0) sum += static_cast<std::uint32_t>(p[n - 1] << 8);
  return sum;
}

std::uint16_t fold(std::uint32_t sum) {
  while (sum >> 16)
    sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum);
}

bool parse_ipv4(const std::string& text, std::uint32_t& out) {
  std::error_code ec;
  const auto address = asio::ip::make_address_v4(text, ec);
  if (ec) return false;
  out = address.to_uint();
  return true;
}

}  // namespace

std::shared_ptr<PcapWriter> PcapWriter::open(const std::filesystem::path& path, PcapOptions options,
                                             std::error_code& ec) {
  ec.clear();
  std::uint32_t client = 0;
  std::uint32_t car = 0;
  if (!parse_ipv4(options.client_address, client) || !parse_ipv4(options.car_address, car)) {
    ec = std::make_error_code(std::errc::invalid_argument);
    return nullptr;
  }
  auto file = CaptureFile::open(path, CaptureFile::Mode::truncate, ec);
  if (!file) return nullptr;
  std::shared_ptr<PcapWriter> writer(
      new PcapWriter(std::move(*file), client, car, std::move(options)));
  std::vector<std::uint8_t> header;
  put_native<std::uint32_t>(header, kMagicNanoseconds);
  put_native<std::uint16_t>(header, 2);  // version 2.4
  put_native<std::uint16_t>(header, 4);
  put_native<std::int32_t>(header, 0);   // timestamps are UTC
  put_native<std::uint32_t>(header, 0);  // accuracy, unused
  put_native<std::uint32_t>(header, kSnapLength);
  put_native<std::uint32_t>(header, kLinktypeRawIpv4);
  if (!writer->file_.write(header)) {
    ec = writer->file_.error();
    return nullptr;
  }
  return writer;
}

PcapWriter::PcapWriter(CaptureFile file, std::uint32_t client_address, std::uint32_t car_address,
                       PcapOptions options)
    : file_(std::move(file)), options_(std::move(options)) {
  if (!options_.wall_clock_us) options_.wall_clock_us = [] { return wall_time_us(); };
  client_.address = client_address;
  car_.address = car_address;
}

PcapWriter::~PcapWriter() = default;

void PcapWriter::begin(Time at) {
  // Link time gives the spacing (exact in virtual time), the wall clock at
  // open gives the date, so a virtual run still lands on the day it ran.
  base_wall_ns_ = options_.wall_clock_us() * 1000;
  base_at_ = at;
  client_.port = static_cast<std::uint16_t>(options_.client_port + connections_);
  car_.port = options_.car_port;
  client_.next_seq = kClientIsn;
  car_.next_seq = kCarIsn;
  client_.fin_sent = false;
  car_.fin_sent = false;
  ++connections_;
  open_ = true;
  reset_seen_ = false;

  write_segment(at, client_, car_, kSyn, {}, true);
  write_segment(at, car_, client_, kSyn | kAck, {}, true);
  write_segment(at, client_, car_, kAck, {}, false);
}

void PcapWriter::on_open(Time at, const std::string& /*client*/, const std::string& /*car*/) {
  begin(at);
}

void PcapWriter::on_delivered(Time at, Direction d, protocol::ByteView bytes) {
  if (bytes.empty()) return;
  // An observer added to a running link still gets a stream Wireshark can
  // follow.
  if (!open_) begin(at);
  Side& from = d == Direction::to_car ? client_ : car_;
  const Side& to = d == Direction::to_car ? car_ : client_;
  for (std::size_t offset = 0; offset < bytes.size(); offset += kPcapMaxSegmentBytes) {
    const auto piece = bytes.subspan(offset, std::min(kPcapMaxSegmentBytes, bytes.size() - offset));
    const bool last = offset + piece.size() == bytes.size();
    write_segment(at, from, to, last ? kPsh | kAck : kAck, piece, false);
  }
}

void PcapWriter::on_fault(const FaultEvent& event) {
  if (event.kind == FaultKind::reset) reset_seen_ = true;
}

void PcapWriter::on_half_close(Time at, Direction d) {
  if (!open_) begin(at);
  Side& sender = d == Direction::to_car ? client_ : car_;
  Side& receiver = d == Direction::to_car ? car_ : client_;
  if (sender.fin_sent) return;
  write_segment(at, sender, receiver, kFin | kAck, {}, false);
  write_segment(at, receiver, sender, kAck, {}, false);
  sender.fin_sent = true;
}

void PcapWriter::on_close(Time at, const LinkClose& close) {
  if (!open_) return;
  // A link broken by hil or by a fault is drawn as the client's doing.
  const bool by_car = close.by == LinkClose::By::car;
  Side& closer = by_car ? car_ : client_;
  Side& other = by_car ? client_ : car_;
  const bool reset = reset_seen_ || close.mode == CloseMode::reset;
  if (reset) {
    write_segment(at, closer, other, kRst | kAck, {}, false);
  } else if (closer.fin_sent || other.fin_sent) {
    // A half-close came first: the side still sending ends now.
    Side& last = closer.fin_sent ? other : closer;
    Side& first = closer.fin_sent ? closer : other;
    if (!last.fin_sent) {
      write_segment(at, last, first, kFin | kAck, {}, false);
      write_segment(at, first, last, kAck, {}, false);
    }
  } else {
    write_segment(at, closer, other, kFin | kAck, {}, false);
    write_segment(at, other, closer, kFin | kAck, {}, false);
    write_segment(at, closer, other, kAck, {}, false);
  }
  open_ = false;
}

void PcapWriter::write_segment(Time at, Side& from, const Side& to, std::uint8_t flags,
                               protocol::ByteView payload, bool announce_mss) {
  const std::size_t tcp_bytes = kTcpHeaderBytes + (announce_mss ? kMssOptionBytes : 0);
  const std::size_t ip_total = kIpHeaderBytes + tcp_bytes + payload.size();
  std::vector<std::uint8_t> packet(ip_total);
  std::uint8_t* ip = packet.data();
  std::uint8_t* tcp = ip + kIpHeaderBytes;

  ip[0] = 0x45;  // IPv4, 5-word header
  put16(ip + 2, static_cast<std::uint16_t>(ip_total));
  put16(ip + 4, from.ip_id++);
  put16(ip + 6, 0x4000);  // don't fragment
  ip[8] = 64;             // TTL
  ip[9] = 6;              // TCP
  put32(ip + 12, from.address);
  put32(ip + 16, to.address);
  put16(ip + 10, fold(sum_words(ip, kIpHeaderBytes)));

  // The receiver has seen everything the other side sent: ack it all.
  const bool acks = (flags & kAck) != 0;
  put16(tcp, from.port);
  put16(tcp + 2, to.port);
  put32(tcp + 4, from.next_seq);
  put32(tcp + 8, acks ? to.next_seq : 0);
  tcp[12] = static_cast<std::uint8_t>((tcp_bytes / 4) << 4);
  tcp[13] = flags;
  put16(tcp + 14, 0xFFFF);  // window
  if (announce_mss) {
    tcp[20] = 2;  // MSS option
    tcp[21] = 4;
    put16(tcp + 22, static_cast<std::uint16_t>(kPcapMaxSegmentBytes));
  }
  if (!payload.empty()) std::memcpy(tcp + tcp_bytes, payload.data(), payload.size());

  const std::size_t tcp_length = tcp_bytes + payload.size();
  std::uint8_t pseudo[12] = {};
  put32(pseudo, from.address);
  put32(pseudo + 4, to.address);
  pseudo[9] = 6;
  put16(pseudo + 10, static_cast<std::uint16_t>(tcp_length));
  put16(tcp + 16, fold(sum_words(tcp, tcp_length, sum_words(pseudo, sizeof pseudo))));

  // SYN and FIN each take one sequence number.
  from.next_seq += static_cast<std::uint32_t>(payload.size());
  if ((flags & (kSyn | kFin)) != 0) ++from.next_seq;

  const auto since_open = std::max(Time{0}, at - base_at_).count();
  const std::int64_t ts_ns = base_wall_ns_ + since_open;
  std::vector<std::uint8_t> record;
  record.reserve(16 + packet.size());
  put_native<std::uint32_t>(record, static_cast<std::uint32_t>(ts_ns / 1'000'000'000));
  put_native<std::uint32_t>(record, static_cast<std::uint32_t>(ts_ns % 1'000'000'000));
  put_native<std::uint32_t>(record, static_cast<std::uint32_t>(packet.size()));
  put_native<std::uint32_t>(record, static_cast<std::uint32_t>(packet.size()));
  record.insert(record.end(), packet.begin(), packet.end());
  file_.write(record);
  if (!file_.error()) ++packets_written_;
}

}  // namespace hil::link
