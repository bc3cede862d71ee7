#pragma once
// Export of a link as a classic pcap file that tshark and Wireshark open: the
// bytes delivered in each direction, wrapped in synthesized IPv4 + TCP
// packets (handshake, sequence and ack numbers, checksums, FIN or RST).
// Layout and timestamps in docs/capture.md.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <system_error>

#include "link/capture/capture_file.hpp"
#include "link/link.hpp"

namespace hil::link {

struct PcapOptions {
  /// The addresses the capture shows. The defaults are a made-up pair for
  /// links that have no IP addresses (mem pipes, ptys); a TCP link can pass
  /// its real ones.
  std::string client_address = "10.0.0.1";  ///< IPv4, dotted
  std::uint16_t client_port = 40000;
  std::string car_address = "10.0.0.2";  ///< IPv4, dotted
  std::uint16_t car_port = 9000;
  /// Source of the wall time that anchors the capture at open (microseconds
  /// since the Unix epoch); wall_time_us() when empty. Tests pin it.
  std::function<std::int64_t()> wall_clock_us;
};

/// The most payload one synthesized segment carries (Ethernet MSS), and
/// what the SYNs announce.
inline constexpr std::size_t kPcapMaxSegmentBytes = 1460;

/// A LinkObserver that writes the "delivered" bytes of a link as a pcap
/// file (nanosecond timestamps, LINKTYPE_RAW: each packet is an IPv4
/// header, a TCP header and the payload). Each packet is written with one
/// write(2) before the callback returns, so the file is readable up to the
/// last packet even if hil crashes.
class PcapWriter final : public LinkObserver {
 public:
  /// Creates (or truncates) `path` and writes the pcap file header. Returns
  /// null and sets `ec` when the file cannot be written or an address in
  /// `options` is not a dotted IPv4 address.
  static std::shared_ptr<PcapWriter> open(const std::filesystem::path& path, PcapOptions options,
                                          std::error_code& ec);
  ~PcapWriter() override;
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  /// Writes the three-way handshake. A second open after a close starts a
  /// new TCP stream from the next client port.
  void on_open(Time at, const std::string& client, const std::string& car) override;
  /// Writes the bytes as data segments of at most kPcapMaxSegmentBytes.
  void on_delivered(Time at, Direction d, protocol::ByteView bytes) override;
  /// Remembers "reset" faults, so the close is written as a reset.
  void on_fault(const FaultEvent& event) override;
  /// Writes the FIN of the side that sends in `d` (the client's for
  /// to_car) and the other side's ACK; the other direction's data follows.
  void on_half_close(Time at, Direction d) override;
  /// Writes FIN, FIN, ACK; or one RST when the link was reset (or a "reset"
  /// fault was seen). The car's side closes when the car closed the link,
  /// the client's side in every other case. After a half-close only the
  /// side that has not sent its FIN yet does: FIN, ACK.
  void on_close(Time at, const LinkClose& close) override;

  /// The first write error, if any.
  std::error_code error() const { return file_.error(); }
  std::uint64_t packets_written() const { return packets_written_; }

 private:
  struct Side {
    std::uint32_t address = 0;  // host order
    std::uint16_t port = 0;
    std::uint32_t next_seq = 0;  // the next sequence number this side sends
    std::uint16_t ip_id = 0;
    bool fin_sent = false;
  };

  PcapWriter(CaptureFile file, std::uint32_t client_address, std::uint32_t car_address,
             PcapOptions options);
  void begin(Time at);
  void write_segment(Time at, Side& from, const Side& to, std::uint8_t flags,
                     protocol::ByteView payload, bool announce_mss);

  CaptureFile file_;
  PcapOptions options_;
  Side client_;
  Side car_;
  bool open_ = false;
  bool reset_seen_ = false;
  std::uint32_t connections_ = 0;
  std::int64_t base_wall_ns_ = 0;
  Time base_at_{0};
  std::uint64_t packets_written_ = 0;
};

}  // namespace hil::link
