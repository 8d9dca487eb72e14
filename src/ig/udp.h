// The IG's and the scripted host's one UDP socket each (POSIX): bound to a port on every
// interface, datagrams in with a timeout, datagrams out to an IPv4 address.
#pragma once

#include <netinet/in.h>

#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::ig {

class UdpSocket {
 public:
  UdpSocket() = default;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  // Binds 0.0.0.0:port (0: the system chooses; port() tells which).
  Status open(uint16_t port);
  uint16_t port() const { return port_; }
  // One datagram into `bytes` and its sender into `from`, waiting at most `timeoutMs` (0: only
  // one already waiting); false when none came.
  bool receive(std::vector<uint8_t>& bytes, sockaddr_in& from, int timeoutMs = 0);
  void send(const std::vector<uint8_t>& bytes, const sockaddr_in& to);

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
};

// A dotted IPv4 address and a port; an error names the address.
Result<sockaddr_in> udpAddress(const std::string& address, uint16_t port);

}  // namespace sv::ig
