#include "saloam/sensors/pcap_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>
#include <pcap/pcap.h>

#include "saloam/core/error.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherVlan = 0x8100;
constexpr std::uint16_t kEtherQinQ = 0x88A8;
constexpr std::uint8_t kProtocolUdp = 17;
constexpr std::size_t kUdpHeader = 8;
constexpr std::size_t kIpv4Header = 20;
constexpr std::size_t kEthernetHeader = 14;
constexpr std::size_t kMaxFragmentData = 1480;  // a 1500-byte MTU less the IPv4 header

std::uint16_t be16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}
std::uint32_t be32(std::span<const std::uint8_t> b, std::size_t at) {
  return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) | (std::uint32_t{b[at + 2]} << 8) |
         std::uint32_t{b[at + 3]};
}
void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v & 0xFF);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  put16(b, at, static_cast<std::uint16_t>(v >> 16));
  put16(b, at + 2, static_cast<std::uint16_t>(v & 0xFFFF));
}

/// The IPv4 packet inside a link-layer frame; empty when it holds none.
std::span<const std::uint8_t> ipv4_of_frame(int link_type, std::span<const std::uint8_t> frame) {
  std::size_t at = 0;
  std::uint16_t ether_type = 0;
  switch (link_type) {
    case DLT_EN10MB:
      if (frame.size() < kEthernetHeader) return {};
      ether_type = be16(frame, 12);
      at = kEthernetHeader;
      while ((ether_type == kEtherVlan || ether_type == kEtherQinQ) && frame.size() >= at + 4) {
        ether_type = be16(frame, at + 2);
        at += 4;
      }
      break;
    case DLT_LINUX_SLL:
      if (frame.size() < 16) return {};
      ether_type = be16(frame, 14);
      at = 16;
      break;
    case DLT_LINUX_SLL2:
      if (frame.size() < 20) return {};
      ether_type = be16(frame, 0);
      at = 20;
      break;
    case DLT_NULL:
    case DLT_LOOP: {
      if (frame.size() < 4) return {};
      const bool ip = frame[0] == 2 || frame[3] == 2;  // AF_INET in either byte order
      ether_type = ip ? kEtherIpv4 : 0;
      at = 4;
      break;
    }
    default:  // raw IP (DLT_RAW, DLT_IPV4)
      if (frame.empty() || (frame[0] >> 4) != 4) return {};
      return frame;
  }
  if (ether_type != kEtherIpv4 || at >= frame.size()) return {};
  return frame.subspan(at);
}

bool link_type_supported(int link_type) {
  static constexpr std::array kTypes{DLT_EN10MB, DLT_LINUX_SLL, DLT_LINUX_SLL2, DLT_NULL, DLT_LOOP, DLT_RAW, DLT_IPV4};
  return std::find(kTypes.begin(), kTypes.end(), link_type) != kTypes.end() || link_type == 101 /* LINKTYPE_RAW */;
}

std::uint16_t ipv4_checksum(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < kIpv4Header; i += 2) sum += static_cast<std::uint32_t>((b[at + i] << 8) | b[at + i + 1]);
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum & 0xFFFF);
}

}  // namespace

// ---------------------------------------------------------------- reassembly

std::optional<Ipv4Reassembler::Datagram> Ipv4Reassembler::add(const Fragment& f) {
  const std::size_t end = f.offset + f.data.size();
  if (end > kMaxDatagramBytes) return std::nullopt;
  const Key key{f.src, f.dst, f.id, f.protocol};
  auto it = pending_.find(key);
  if (it == pending_.end()) {
    if (pending_.size() >= kMaxPendingDatagrams) {  // the oldest unfinished one goes
      auto oldest = std::min_element(pending_.begin(), pending_.end(),
                                     [](const auto& a, const auto& b) { return a.second.age < b.second.age; });
      pending_.erase(oldest);
      ++dropped_;
    }
    it = pending_.emplace(key, Pending{}).first;
    it->second.file_offset = f.file_offset;
  }
  Pending& p = it->second;
  p.age = ++clock_;
  if (p.bytes.size() < end) {
    p.bytes.resize(end);
    p.have.resize((end + 7) / 8, false);
  }
  std::copy(f.data.begin(), f.data.end(), p.bytes.begin() + static_cast<std::ptrdiff_t>(f.offset));
  for (std::size_t unit = f.offset / 8; unit < (end + 7) / 8; ++unit) p.have[unit] = true;
  if (!f.more) p.total = end;
  if (!p.total || p.bytes.size() < *p.total) return std::nullopt;
  const std::size_t units = (*p.total + 7) / 8;
  if (!std::all_of(p.have.begin(), p.have.begin() + static_cast<std::ptrdiff_t>(units), [](bool b) { return b; })) {
    return std::nullopt;
  }
  Datagram done{std::move(p.bytes), p.file_offset};
  done.bytes.resize(*p.total);
  pending_.erase(it);
  return done;
}

void Ipv4Reassembler::clear() {
  dropped_ += pending_.size();
  pending_.clear();
}

// ---------------------------------------------------------------- reading

struct PcapReader::Handle {
  pcap_t* pcap = nullptr;
  ~Handle() {
    if (pcap) pcap_close(pcap);
  }
};

PcapReader::PcapReader(fs::path file) : file_(std::move(file)), handle_(std::make_unique<Handle>()) {
  std::array<char, PCAP_ERRBUF_SIZE> error{};
  handle_->pcap = pcap_open_offline(file_.c_str(), error.data());
  if (!handle_->pcap) throw InputError(file_, fmt::format("not a readable packet capture: {}", error.data()));
  link_type_ = pcap_datalink(handle_->pcap);
  if (!link_type_supported(link_type_)) {
    const char* name = pcap_datalink_val_to_name(link_type_);
    throw InputError(file_, fmt::format("capture of link type {} ({}): saloam reads Ethernet, Linux cooked, "
                                        "raw IPv4 and loopback captures",
                                        link_type_, name ? name : "unknown"));
  }
}

PcapReader::~PcapReader() = default;

std::int64_t PcapReader::offset() const { return static_cast<std::int64_t>(std::ftell(pcap_file(handle_->pcap))); }

void PcapReader::seek(std::int64_t offset) {
  if (std::fseek(pcap_file(handle_->pcap), static_cast<long>(offset), SEEK_SET) != 0) {
    throw InputError(file_, fmt::format("cannot seek to byte {}", offset));
  }
  reassembler_.clear();
}

bool PcapReader::next(UdpDatagram& out) {
  while (true) {
    const std::int64_t at = offset();
    pcap_pkthdr* header = nullptr;
    const u_char* data = nullptr;
    const int status = pcap_next_ex(handle_->pcap, &header, &data);
    if (status == PCAP_ERROR_BREAK) {
      counts_.incomplete = reassembler_.dropped();
      return false;
    }
    if (status < 0) {
      throw InputError(file_, fmt::format("corrupt capture record at byte {}: {}", at, pcap_geterr(handle_->pcap)));
    }
    ++counts_.records;
    const double time = static_cast<double>(header->ts.tv_sec) + 1e-6 * static_cast<double>(header->ts.tv_usec);
    if (header->caplen < header->len) {
      ++counts_.malformed;  // cut by the snap length: the payload is not all there
      continue;
    }
    if (take_record({data, header->caplen}, time, at, out)) {
      ++counts_.datagrams;
      counts_.incomplete = reassembler_.dropped();
      return true;
    }
  }
}

bool PcapReader::take_record(std::span<const std::uint8_t> frame, double time, std::int64_t offset,
                             UdpDatagram& out) {
  const auto ip = ipv4_of_frame(link_type_, frame);
  if (ip.empty()) {
    ++counts_.not_udp;
    return false;
  }
  return take_ipv4(ip, time, offset, out);
}

bool PcapReader::take_ipv4(std::span<const std::uint8_t> ip, double time, std::int64_t offset, UdpDatagram& out) {
  if (ip.size() < kIpv4Header || (ip[0] >> 4) != 4) {
    ++counts_.malformed;
    return false;
  }
  const std::size_t header = std::size_t{ip[0] & 0x0Fu} * 4;
  const std::size_t total = be16(ip, 2);
  if (header < kIpv4Header || total < header || total > ip.size()) {
    ++counts_.malformed;
    return false;
  }
  const std::uint8_t protocol = ip[9];
  if (protocol != kProtocolUdp) {
    ++counts_.not_udp;
    return false;
  }
  const std::uint32_t src = be32(ip, 12);
  const std::uint32_t dst = be32(ip, 16);
  const std::uint16_t flags = be16(ip, 6);
  const bool more = (flags & 0x2000) != 0;
  const std::size_t fragment_offset = std::size_t{flags & 0x1FFFu} * 8;
  const auto body = ip.subspan(header, total - header);
  if (!more && fragment_offset == 0) return take_udp(body, src, dst, time, offset, out);
  ++counts_.fragments;
  auto whole = reassembler_.add({src, dst, be16(ip, 4), protocol, fragment_offset, more, body, offset});
  if (!whole) return false;
  return take_udp(whole->bytes, src, dst, time, whole->file_offset, out);
}

bool PcapReader::take_udp(std::span<const std::uint8_t> udp, std::uint32_t src, std::uint32_t dst, double time,
                          std::int64_t offset, UdpDatagram& out) {
  if (udp.size() < kUdpHeader) {
    ++counts_.malformed;
    return false;
  }
  const std::size_t length = be16(udp, 4);
  if (length < kUdpHeader || length > udp.size()) {
    ++counts_.malformed;
    return false;
  }
  out.time = time;
  out.src_ip = src;
  out.dst_ip = dst;
  out.src_port = be16(udp, 0);
  out.dst_port = be16(udp, 2);
  out.payload.assign(udp.begin() + kUdpHeader, udp.begin() + static_cast<std::ptrdiff_t>(length));
  out.offset = offset;
  return true;
}

// ---------------------------------------------------------------- writing

struct PcapWriter::Handle {
  pcap_t* pcap = nullptr;
  pcap_dumper_t* dumper = nullptr;
  ~Handle() {
    if (dumper) pcap_dump_close(dumper);
    if (pcap) pcap_close(pcap);
  }
};

PcapWriter::PcapWriter(const fs::path& file) : handle_(std::make_unique<Handle>()), file_(file) {
  handle_->pcap = pcap_open_dead(DLT_EN10MB, 65535);
  if (!handle_->pcap) throw InputError(file_, "cannot start a capture (libpcap)");
  handle_->dumper = pcap_dump_open(handle_->pcap, file_.c_str());
  if (!handle_->dumper) throw InputError(file_, fmt::format("cannot create: {}", pcap_geterr(handle_->pcap)));
}

PcapWriter::~PcapWriter() = default;

void PcapWriter::close() {
  if (handle_->dumper) {
    pcap_dump_close(handle_->dumper);
    handle_->dumper = nullptr;
  }
}

void PcapWriter::write(double time, std::span<const std::uint8_t> payload, std::uint16_t dst_port,
                       std::uint32_t src_ip, std::uint32_t dst_ip) {
  std::vector<std::uint8_t> udp(kUdpHeader + payload.size());
  put16(udp, 0, dst_port);
  put16(udp, 2, dst_port);
  put16(udp, 4, static_cast<std::uint16_t>(udp.size()));  // checksum 0: none (allowed over IPv4)
  std::copy(payload.begin(), payload.end(), udp.begin() + kUdpHeader);
  const std::uint16_t id = next_id_++;
  for (std::size_t at = 0; at < udp.size(); at += kMaxFragmentData) {
    const std::size_t n = std::min(kMaxFragmentData, udp.size() - at);
    const bool more = at + n < udp.size();
    std::vector<std::uint8_t> frame(kEthernetHeader + kIpv4Header + n, 0);
    for (std::size_t i = 0; i < 6; ++i) frame[i] = 0xFF;              // broadcast destination
    for (std::size_t i = 6; i < 12; ++i) frame[i] = 0x02;             // a locally administered source
    put16(frame, 12, kEtherIpv4);
    const std::size_t ip = kEthernetHeader;
    frame[ip] = 0x45;
    put16(frame, ip + 2, static_cast<std::uint16_t>(kIpv4Header + n));
    put16(frame, ip + 4, id);
    put16(frame, ip + 6, static_cast<std::uint16_t>((more ? 0x2000 : 0) | (at / 8)));
    frame[ip + 8] = 64;
    frame[ip + 9] = kProtocolUdp;
    put32(frame, ip + 12, src_ip);
    put32(frame, ip + 16, dst_ip);
    put16(frame, ip + 10, ipv4_checksum(frame, ip));
    std::copy_n(udp.begin() + static_cast<std::ptrdiff_t>(at), n, frame.begin() + kEthernetHeader + kIpv4Header);
    write_frame(time, frame);
  }
}

void PcapWriter::write_frame(double time, std::span<const std::uint8_t> frame) {
  if (!handle_->dumper) throw InputError(file_, "capture already closed");
  pcap_pkthdr header{};
  const double seconds = std::floor(time);
  header.ts.tv_sec = static_cast<decltype(header.ts.tv_sec)>(seconds);
  auto micros = static_cast<long>(std::llround((time - seconds) * 1e6));
  if (micros >= 1000000) {
    ++header.ts.tv_sec;
    micros -= 1000000;
  }
  header.ts.tv_usec = static_cast<decltype(header.ts.tv_usec)>(micros);
  header.caplen = static_cast<bpf_u_int32>(frame.size());
  header.len = header.caplen;
  pcap_dump(reinterpret_cast<u_char*>(handle_->dumper), &header, frame.data());
}

bool has_pcap_magic(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<unsigned char, 4> m{};
  if (!in.read(reinterpret_cast<char*>(m.data()), 4)) return false;
  const std::uint32_t le = m[0] | (m[1] << 8) | (m[2] << 16) | (std::uint32_t{m[3]} << 24);
  constexpr std::array<std::uint32_t, 5> kMagics{0xA1B2C3D4U, 0xD4C3B2A1U, 0xA1B23C4DU, 0x4D3CB2A1U,
                                                 0x0A0D0D0AU /* pcapng */};
  return std::find(kMagics.begin(), kMagics.end(), le) != kMagics.end();
}

}  // namespace saloam
