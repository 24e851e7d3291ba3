#pragma once
// Packet captures (libpcap "savefile" format, also pcapng through libpcap)
// read as the UDP datagrams they hold, and written: the transport under the
// sensor decoders (ouster_packet.hpp, velodyne_packet.hpp), which see only
// payload bytes, so that a live UDP socket can feed them the same way.
//
// Reading: pcap_open_offline; link layers Ethernet (with 802.1Q / 802.1ad
// VLAN tags), Linux cooked capture v1 and v2, raw IPv4 and BSD loopback.
// IPv4 only (IPv6 and other protocols are counted and skipped). Fragmented
// IPv4 datagrams (a 16 kB Ouster packet over a 1500-byte MTU) are put back
// together from their fragments (RFC 791: by source, destination, protocol
// and identification; any order; overlaps taken as they come), at most
// kMaxPendingDatagrams at a time and kMaxDatagramBytes each, so that a
// corrupt capture cannot hold unbounded memory: a datagram whose fragments
// never complete is dropped (counted) when the table is full or the capture
// ends. A record cut short by the capture's snap length, a bad IPv4 header or
// a UDP length that does not fit is counted as malformed and skipped. A file
// that is not a capture, or whose record headers are corrupt (libpcap stops
// with an error), is an InputError naming the file.
//
// Times are the capture's record times [s since the epoch] (the recording
// PC's clock); a datagram's time is its last fragment's.
//
// Positions: offset() before a read is where the next record starts in the
// file; seek() goes back there (for a source that serves any frame: it
// remembers where each frame's packets are, not the packets). A datagram's
// offset is that of the record holding its first fragment seen.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <tuple>
#include <vector>

namespace saloam {

struct UdpDatagram {
  double time = 0.0;              ///< [s since the epoch] capture time
  std::uint32_t src_ip = 0;       ///< IPv4 address, host order
  std::uint32_t dst_ip = 0;
  std::uint16_t src_port = 0;
  std::uint16_t dst_port = 0;
  std::vector<std::uint8_t> payload;  ///< the UDP payload
  std::int64_t offset = 0;        ///< file position of its (first) record
};

/// What a capture held besides the datagrams returned.
struct PcapCounts {
  std::size_t records = 0;       ///< capture records read
  std::size_t datagrams = 0;     ///< UDP datagrams returned
  std::size_t fragments = 0;     ///< records that were IPv4 fragments
  std::size_t not_udp = 0;       ///< records of other protocols (IPv6, ARP, TCP, ...)
  std::size_t malformed = 0;     ///< records cut short or with bad headers
  std::size_t incomplete = 0;    ///< fragmented datagrams dropped unfinished
};

inline constexpr std::size_t kMaxPendingDatagrams = 64;
inline constexpr std::size_t kMaxDatagramBytes = 65535;

/// Puts IPv4 fragments back together (RFC 791), bounded as said above.
class Ipv4Reassembler {
 public:
  struct Fragment {
    std::uint32_t src = 0, dst = 0;
    std::uint16_t id = 0;
    std::uint8_t protocol = 0;
    std::size_t offset = 0;  ///< [bytes] of this fragment's data in the datagram
    bool more = false;       ///< more fragments follow
    std::span<const std::uint8_t> data;
    std::int64_t file_offset = 0;
  };
  struct Datagram {
    std::vector<std::uint8_t> bytes;  ///< the IP payload (UDP header and data)
    std::int64_t file_offset = 0;
  };
  /// The whole datagram once `fragment` completes it; nullopt before, or
  /// when the fragment cannot belong to any (beyond kMaxDatagramBytes).
  std::optional<Datagram> add(const Fragment& fragment);
  /// Datagrams dropped unfinished so far (the table full, or clear()).
  [[nodiscard]] std::size_t dropped() const { return dropped_; }
  void clear();

 private:
  struct Pending {
    std::vector<std::uint8_t> bytes;
    std::vector<bool> have;           ///< per 8-byte unit received
    std::optional<std::size_t> total;  ///< known once the last fragment came
    std::int64_t file_offset = 0;
    std::uint64_t age = 0;
  };
  using Key = std::tuple<std::uint32_t, std::uint32_t, std::uint16_t, std::uint8_t>;
  std::map<Key, Pending> pending_;
  std::uint64_t clock_ = 0;
  std::size_t dropped_ = 0;
};

class PcapReader {
 public:
  /// InputError naming `file` when it cannot be opened as a capture or its
  /// link layer is none of those above.
  explicit PcapReader(std::filesystem::path file);
  ~PcapReader();
  PcapReader(const PcapReader&) = delete;
  PcapReader& operator=(const PcapReader&) = delete;

  /// The next UDP datagram; false at the end of the capture. InputError
  /// naming the file when libpcap reports a corrupt record.
  bool next(UdpDatagram& out);
  /// Where the next record starts.
  [[nodiscard]] std::int64_t offset() const;
  /// Continues from a position offset() returned; pending fragments are dropped.
  void seek(std::int64_t offset);

  [[nodiscard]] const PcapCounts& counts() const { return counts_; }
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  /// The datagram in one record, if it is (or completes) a UDP datagram.
  bool take_record(std::span<const std::uint8_t> frame, double time, std::int64_t offset, UdpDatagram& out);
  bool take_ipv4(std::span<const std::uint8_t> ip, double time, std::int64_t offset, UdpDatagram& out);
  bool take_udp(std::span<const std::uint8_t> udp, std::uint32_t src, std::uint32_t dst, double time,
                std::int64_t offset, UdpDatagram& out);

  std::filesystem::path file_;
  struct Handle;
  std::unique_ptr<Handle> handle_;
  int link_type_ = 0;
  Ipv4Reassembler reassembler_;
  PcapCounts counts_;
};

/// Writes a capture (Ethernet, IPv4, UDP; microsecond times) through
/// libpcap: what the simulator's sensor captures are, and tests' corrupt
/// inputs start from. An existing file is replaced.
class PcapWriter {
 public:
  /// InputError naming `file` when it cannot be created.
  explicit PcapWriter(const std::filesystem::path& file);
  ~PcapWriter();
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  /// One UDP datagram at `time` [s since the epoch, >= 0] from
  /// src_ip:dst_port (source port the same) to dst_ip:dst_port; payloads over
  /// 1472 bytes are written as IPv4 fragments of at most 1480 data bytes
  /// each, as a 1500-byte MTU network carries them.
  void write(double time, std::span<const std::uint8_t> payload, std::uint16_t dst_port,
             std::uint32_t src_ip = 0xC0A8010AU /* 192.168.1.10 */,
             std::uint32_t dst_ip = 0xC0A801FFU /* 192.168.1.255 */);
  void close();

 private:
  void write_frame(double time, std::span<const std::uint8_t> frame);

  struct Handle;
  std::unique_ptr<Handle> handle_;
  std::filesystem::path file_;
  std::uint16_t next_id_ = 1;
};

/// True when `file` starts with a pcap or pcapng magic number.
[[nodiscard]] bool has_pcap_magic(const std::filesystem::path& file);

}  // namespace saloam
