// Based on: the classic libpcap file format (tcpdump.org, "pcap-savefile(5)"; IETF draft
// draft-ietf-opsawg-pcap: a 24-byte global header, 16-byte record headers); Ethernet II framing;
// RFC 791 (IPv4, its header checksum: the one's complement of the one's complement sum of the
// header's 16-bit words); RFC 768 (UDP; a checksum of 0 means "none" over IPv4).
#include "cigi/pcap.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "synthvis/cigi.h"
#include "synthvis/files.h"

namespace sv::cigi {
namespace {

constexpr uint32_t kMagicMicro = 0xa1b2c3d4, kMagicNano = 0xa1b23c4d;
constexpr uint32_t kLinkTypeEthernet = 1;
constexpr size_t kGlobalHeader = 24, kRecordHeader = 16;
constexpr size_t kEthernetHeader = 14, kIpv4Header = 20, kUdpHeader = 8;
constexpr size_t kFrameHeaders = kEthernetHeader + kIpv4Header + kUdpHeader;
// IPv4's total length is 16 bits: what is left for a UDP payload.
constexpr size_t kMaxUdpPayload = 65535 - kIpv4Header - kUdpHeader;  // 65507
// Records longer than this are refused as absurd (a CIGI datagram is at most 64 KiB).
constexpr size_t kMaxRecord = 256 * 1024;
constexpr uint32_t kSnapLength = kMaxRecord;
constexpr uint16_t kEtherTypeIpv4 = 0x0800;
constexpr uint8_t kIpProtocolUdp = 17;

// The two ends (docs/cigi.md): the host at 127.0.0.1, the IG at 127.0.0.2, with locally
// administered MAC addresses.
constexpr uint8_t kHostIp[4] = {127, 0, 0, 1}, kIgIp[4] = {127, 0, 0, 2};
constexpr uint8_t kHostMac[6] = {0x02, 0, 0, 0, 0, 0x01}, kIgMac[6] = {0x02, 0, 0, 0, 0, 0x02};

// The pcap headers are written little-endian (as libpcap does on x86); the network headers are
// big-endian, as on the wire.
void putLe32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
void putLe16(uint8_t* p, uint16_t v) { p[0] = uint8_t(v), p[1] = uint8_t(v >> 8); }
void putBe16(uint8_t* p, uint16_t v) { p[0] = uint8_t(v >> 8), p[1] = uint8_t(v); }
uint16_t getBe16(const uint8_t* p) { return uint16_t(p[0] << 8 | p[1]); }
uint32_t get32(const uint8_t* p, bool bigEndian) {
  return bigEndian ? uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]
                   : uint32_t(p[3]) << 24 | uint32_t(p[2]) << 16 | uint32_t(p[1]) << 8 | p[0];
}

// RFC 791 §3.1 (computed as RFC 1071 describes): the sum of the header's 16-bit words, carries
// folded back in, complemented.
uint16_t ipv4Checksum(const uint8_t* header) {
  uint32_t sum = 0;
  for (size_t i = 0; i < kIpv4Header; i += 2) sum += getBe16(header + i);
  while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
  return uint16_t(~sum);
}

Error fileError(const std::string& file, std::string message, size_t byte = SIZE_MAX) {
  return Error{file, byte == SIZE_MAX ? "" : fmt::format("byte {}", byte), std::move(message)};
}

// Writes all of `bytes` and flushes, or says why not.
Status writeAll(std::FILE* f, const std::string& path, const uint8_t* bytes, size_t n) {
  errno = 0;
  if (std::fwrite(bytes, 1, n, f) != n || std::fflush(f) != 0) {
    return fileError(path, fmt::format("cannot write: {}", core::writeFailure(errno)));
  }
  return {};
}

}  // namespace

PcapWriter::~PcapWriter() { close(); }

void PcapWriter::close() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
}

Status PcapWriter::open(const std::string& path) {
  close();
  path_ = path;
  ipId_ = 0;
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) return fileError(path, fmt::format("cannot create: {}", std::strerror(errno)));
  uint8_t h[kGlobalHeader] = {};
  putLe32(h, kMagicMicro);
  putLe16(h + 4, 2);  // format version 2.4
  putLe16(h + 6, 4);
  // Bytes 8-15: the time zone offset and the timestamps' accuracy, both 0 by convention.
  putLe32(h + 16, kSnapLength);
  putLe32(h + 20, kLinkTypeEthernet);
  return writeAll(file_, path_, h, sizeof h);
}

Status PcapWriter::add(const CapturedDatagram& d) {
  if (!file_) return fileError(path_, "capture not open");
  if (!(d.time >= 0) || !std::isfinite(d.time) || d.time >= 4294967296.0) {
    return fileError(path_, fmt::format("time {} s is not a capture time", d.time));
  }
  const size_t n = d.bytes.size();
  if (n > kMaxUdpPayload) {
    return fileError(path_, fmt::format("datagram of {} bytes is more than UDP carries ({})", n,
                                        kMaxUdpPayload));
  }
  // Seconds and microseconds, the rounding carried into the seconds.
  auto seconds = uint64_t(std::floor(d.time));
  auto micros = uint64_t(std::llround((d.time - double(seconds)) * 1e6));
  if (micros >= 1000000) ++seconds, micros -= 1000000;

  std::vector<uint8_t> record(kRecordHeader + kFrameHeaders + n, 0);
  uint8_t* r = record.data();
  putLe32(r, uint32_t(seconds));
  putLe32(r + 4, uint32_t(micros));
  putLe32(r + 8, uint32_t(kFrameHeaders + n));   // captured length
  putLe32(r + 12, uint32_t(kFrameHeaders + n));  // length on the wire
  // Ethernet II: destination, source, EtherType.
  uint8_t* eth = r + kRecordHeader;
  std::memcpy(eth, d.fromHost ? kIgMac : kHostMac, 6);
  std::memcpy(eth + 6, d.fromHost ? kHostMac : kIgMac, 6);
  putBe16(eth + 12, kEtherTypeIpv4);
  // IPv4 (RFC 791 §3.1): version 4 and 5 words of header, total length, identification, "don't
  // fragment", TTL 64, UDP, the checksum (over the header with its own field 0), source, dest.
  uint8_t* ip = eth + kEthernetHeader;
  ip[0] = 0x45;
  putBe16(ip + 2, uint16_t(kIpv4Header + kUdpHeader + n));
  putBe16(ip + 4, ipId_++);
  putBe16(ip + 6, 0x4000);
  ip[8] = 64;
  ip[9] = kIpProtocolUdp;
  std::memcpy(ip + 12, d.fromHost ? kHostIp : kIgIp, 4);
  std::memcpy(ip + 16, d.fromHost ? kIgIp : kHostIp, 4);
  putBe16(ip + 10, ipv4Checksum(ip));
  // UDP (RFC 768): ports, length, checksum 0 ("not computed", allowed over IPv4).
  uint8_t* udp = ip + kIpv4Header;
  putBe16(udp, d.fromHost ? kHostPort : kIgPort);
  putBe16(udp + 2, d.fromHost ? kIgPort : kHostPort);
  putBe16(udp + 4, uint16_t(kUdpHeader + n));
  if (n) std::memcpy(udp + kUdpHeader, d.bytes.data(), n);
  return writeAll(file_, path_, record.data(), record.size());
}

Status writePcap(const std::string& path, std::span<const CapturedDatagram> datagrams) {
  PcapWriter writer;
  if (Status s = writer.open(path); !s) return s;
  for (const CapturedDatagram& d : datagrams) {
    if (Status s = writer.add(d); !s) return s;
  }
  return {};
}

Result<std::vector<CapturedDatagram>> parsePcap(std::span<const uint8_t> bytes,
                                                const std::string& name) {
  // Step 1: the global header — its magic gives the byte order and the timestamps' unit.
  if (bytes.size() < kGlobalHeader) {
    return fileError(name, fmt::format("{} bytes, shorter than a pcap header", bytes.size()), 0);
  }
  bool bigEndian = false;
  double fractionUnit = 1e-6;
  const uint32_t le = get32(bytes.data(), false), be = get32(bytes.data(), true);
  if (le == kMagicMicro || le == kMagicNano) {
    fractionUnit = le == kMagicNano ? 1e-9 : 1e-6;
  } else if (be == kMagicMicro || be == kMagicNano) {
    bigEndian = true;
    fractionUnit = be == kMagicNano ? 1e-9 : 1e-6;
  } else {
    return fileError(name, fmt::format("bad magic {:#010x}: not a classic pcap file", be), 0);
  }
  const uint32_t linkType = get32(bytes.data() + 20, bigEndian) & 0x0fffffff;
  if (linkType != kLinkTypeEthernet) {
    return fileError(name, fmt::format("link type {}, not Ethernet (1)", linkType), 20);
  }
  // Step 2: records, each an Ethernet frame holding IPv4 and UDP.
  std::vector<CapturedDatagram> out;
  size_t at = kGlobalHeader;
  while (at < bytes.size()) {
    const size_t left = bytes.size() - at;
    if (left < kRecordHeader) {
      return fileError(name, fmt::format("truncated record header ({} bytes)", left), at);
    }
    const uint8_t* r = bytes.data() + at;
    const uint32_t seconds = get32(r, bigEndian), fraction = get32(r + 4, bigEndian);
    const uint32_t length = get32(r + 8, bigEndian);
    if (length > kMaxRecord) {
      return fileError(name, fmt::format("record of {} bytes, more than 256 KiB", length), at + 8);
    }
    if (length > left - kRecordHeader) {
      return fileError(name, fmt::format("truncated record: {} bytes, {} left", length,
                                         left - kRecordHeader), at + 8);
    }
    const size_t frameAt = at + kRecordHeader;
    const uint8_t* f = r + kRecordHeader;
    if (length < kEthernetHeader + kIpv4Header) {
      return fileError(name, fmt::format("frame of {} bytes, too short for IPv4", length),
                       frameAt);
    }
    if (getBe16(f + 12) != kEtherTypeIpv4) {
      return fileError(name, fmt::format("EtherType {:#06x}, not IPv4", getBe16(f + 12)),
                       frameAt + 12);
    }
    const uint8_t* ip = f + kEthernetHeader;
    const size_t ipAt = frameAt + kEthernetHeader, ipRoom = length - kEthernetHeader;
    const size_t ipHeader = size_t(ip[0] & 0x0f) * 4, ipTotal = getBe16(ip + 2);
    if ((ip[0] >> 4) != 4 || ipHeader < kIpv4Header || ipTotal < ipHeader + kUdpHeader ||
        ipTotal > ipRoom) {
      return fileError(name, "malformed IPv4 header", ipAt);
    }
    if (ip[9] != kIpProtocolUdp) {
      return fileError(name, fmt::format("IP protocol {}, not UDP (17)", ip[9]), ipAt + 9);
    }
    const uint8_t* udp = ip + ipHeader;
    const size_t udpLength = getBe16(udp + 4);
    if (udpLength < kUdpHeader || udpLength > ipTotal - ipHeader) {
      return fileError(name, fmt::format("UDP length {} does not fit its IPv4 packet", udpLength),
                       ipAt + ipHeader + 4);
    }
    CapturedDatagram d;
    d.time = double(seconds) + double(fraction) * fractionUnit;
    d.fromHost = getBe16(udp + 2) == kIgPort;
    d.bytes.assign(udp + kUdpHeader, udp + udpLength);
    out.push_back(std::move(d));
    at = frameAt + length;
  }
  return out;
}

Result<std::vector<CapturedDatagram>> readPcap(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return fileError(path, fmt::format("cannot open: {}", std::strerror(errno)));
  std::vector<uint8_t> bytes;
  uint8_t chunk[65536];
  size_t n;
  while ((n = std::fread(chunk, 1, sizeof chunk, f.get())) > 0) {
    bytes.insert(bytes.end(), chunk, chunk + n);
  }
  if (std::ferror(f.get())) return fileError(path, "read error");
  return parsePcap(bytes, path);
}

}  // namespace sv::cigi
