// POSIX UDP for the IG and the scripted host (ig/udp.h).
#include "ig/udp.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace sv::ig {

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

Status UdpSocket::open(uint16_t port) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    return Error{"", "", fmt::format("cannot open a UDP socket: {}", std::strerror(errno))};
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = htons(port);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0)
    return Error{"", "", fmt::format("cannot listen on UDP port {}: {}", port, std::strerror(errno))};
  socklen_t len = sizeof a;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);
  return {};
}

bool UdpSocket::receive(std::vector<uint8_t>& bytes, sockaddr_in& from, int timeoutMs) {
  if (timeoutMs > 0) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, timeoutMs) <= 0) return false;
  }
  bytes.resize(65536);
  socklen_t len = sizeof from;
  const ssize_t n = ::recvfrom(fd_, bytes.data(), bytes.size(), 0,
                               reinterpret_cast<sockaddr*>(&from), &len);
  if (n < 0) return false;
  bytes.resize(size_t(n));
  return true;
}

void UdpSocket::send(const std::vector<uint8_t>& bytes, const sockaddr_in& to) {
  ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
}

Result<sockaddr_in> udpAddress(const std::string& address, uint16_t port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1)
    return Error{"", "", fmt::format("\"{}\" is not a dotted IPv4 address", address)};
  return a;
}

}  // namespace sv::ig
