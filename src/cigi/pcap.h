// Captures of CIGI sessions as classic libpcap files (the tcpdump format: link type 1, Ethernet
// II / IPv4 / UDP, microsecond timestamps), written and read by our own code — no libpcap. Host
// datagrams travel from 127.0.0.1:kHostPort to 127.0.0.2:kIgPort, the IG's answers back, so that
// Wireshark decodes a capture with `-d udp.port==8004,cigi -d udp.port==8005,cigi` (docs/cigi.md).
#pragma once

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::cigi {

struct CapturedDatagram {
  double time = 0;        // seconds since the epoch (or since the session began), ≥ 0
  bool fromHost = true;   // host → IG (else IG → host)
  std::vector<uint8_t> bytes;  // the UDP payload: one CIGI datagram, at most 65507 bytes
};

// Writes a capture, record by record, flushing each so that a killed process still leaves a
// readable file (at worst without the record it was writing).
class PcapWriter {
 public:
  PcapWriter() = default;
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;
  ~PcapWriter();

  // Creates (or truncates) the file and writes the global header.
  Status open(const std::string& path);
  // Appends one datagram as an Ethernet/IPv4/UDP frame. Errors: not open, a time that is negative
  // or not finite, a datagram too long for UDP, a failed write.
  Status add(const CapturedDatagram& datagram);
  // Closes the file (the destructor does too).
  void close();

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  uint16_t ipId_ = 0;  // the IPv4 identification field, one per record
};

// A whole capture at once.
Status writePcap(const std::string& path, std::span<const CapturedDatagram> datagrams);

// Reads a capture written as above (either byte order of the pcap headers; micro- or nanosecond
// timestamps). Refuses, with one line naming the file: a bad magic, a link type other than
// Ethernet, a truncated header or record, a record longer than 256 KiB, a frame that is not
// IPv4/UDP. A datagram is from the host when its UDP destination port is kIgPort.
Result<std::vector<CapturedDatagram>> readPcap(const std::string& path);
// The same on a file's bytes in memory; `name` stands for the file in errors.
Result<std::vector<CapturedDatagram>> parsePcap(std::span<const uint8_t> bytes,
                                                const std::string& name);

}  // namespace sv::cigi
