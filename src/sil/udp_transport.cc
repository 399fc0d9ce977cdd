// UDP: one frame per datagram on a socket bound to the given address (127.0.0.1 by default).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "sil/transport.h"

namespace recruit::sil {
namespace {

class UdpTransport : public Transport {
 public:
  UdpTransport(int fd, sockaddr_in self) : fd_(fd), self_(self) {}
  ~UdpTransport() override { ::close(fd_); }

  std::optional<Frame> Receive(Clock::time_point deadline, Refused& refused) override {
    std::uint8_t buf[kMaxFrameSize + 1];
    for (;;) {
      pollfd p{fd_, POLLIN, 0};
      const int r = ::poll(&p, 1, MillisecondsUntil(deadline));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) return std::nullopt;
      sockaddr_in from{};
      socklen_t len = sizeof from;
      // MSG_TRUNC: the datagram's real length, so that an oversized one is known as such.
      const ssize_t n = ::recvfrom(fd_, buf, sizeof buf, MSG_TRUNC | MSG_DONTWAIT,
                                   reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) {
        if (Clock::now() >= deadline) return std::nullopt;
        continue;  // e.g. ICMP port unreachable reported on the socket
      }
      if (has_peer_ && !SameAddress(from, peer_)) {
        ++refused.foreign;
        continue;
      }
      Frame f;
      const ParseError e = static_cast<std::size_t>(n) > kMaxFrameSize
                               ? ParseError::kOversized
                               : ParseFrame(buf, static_cast<std::size_t>(n), f);
      if (e != ParseError::kNone) {
        refused.Count(e);
        continue;
      }
      if (!has_peer_) {
        if (f.type != FrameType::kHello) {
          ++refused.malformed;  // nothing but a hello before the controller is known
          continue;
        }
        peer_ = from;
        has_peer_ = true;
      }
      return f;
    }
  }

  Status Send(const std::vector<std::uint8_t>& frame) override {
    if (!has_peer_) return Error{"udp: no controller yet"};
    const ssize_t n = ::sendto(fd_, frame.data(), frame.size(), 0,
                               reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_);
    // A controller that went away (ECONNREFUSED from an earlier datagram) is not an error of
    // the plant: its answers will be missing and counted as lost.
    if (n < 0 && errno != ECONNREFUSED) {
      return IoError(std::string("udp: cannot send: ") + std::strerror(errno));
    }
    return Status::Ok();
  }

  std::string Describe() const override {
    char a[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &self_.sin_addr, a, sizeof a);
    return "udp " + std::string(a) + ":" + std::to_string(ntohs(self_.sin_port));
  }

 private:
  static bool SameAddress(const sockaddr_in& a, const sockaddr_in& b) {
    return a.sin_addr.s_addr == b.sin_addr.s_addr && a.sin_port == b.sin_port;
  }
  int fd_;
  sockaddr_in self_;
  sockaddr_in peer_{};
  bool has_peer_ = false;
};

}  // namespace

Result<std::unique_ptr<Transport>> OpenUdp(const std::string& address, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (port < 0 || port > 65535 || ::inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    return Error{"--bind '" + address + "' / --udp " + std::to_string(port) +
                 ": not an IPv4 address and port (0-65535)"};
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return IoError(std::string("udp: cannot create a socket: ") + std::strerror(errno));
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return IoError("udp: cannot bind " + address + ":" + std::to_string(port) + ": " + why);
  }
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  return std::unique_ptr<Transport>(new UdpTransport(fd, a));
}

}  // namespace recruit::sil
