// The byte channels of `recruit sil` (docs/sil.md): UDP datagrams on a bound address (one frame
// per datagram) and a pseudo-terminal (a byte stream, as a USB serial device appears). Both
// deliver parsed frames and count what they refuse.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "sil/protocol.h"

namespace recruit::sil {

using Clock = std::chrono::steady_clock;

// Packets (or stream candidates) refused before the plant saw them.
struct Refused {
  long malformed = 0;   // bad sync, type, bundle count, CRC or probability
  long truncated = 0;   // shorter than its frame (datagrams; in a stream it fails the CRC)
  long oversized = 0;   // longer than its frame (datagrams)
  long foreign = 0;     // datagrams from another address than the controller's (UDP)
  long junk_bytes = 0;  // bytes between frames (pseudo-terminal)
  void Count(ParseError e);
};

// poll()'s timeout until `deadline`, ms (0 once it has passed).
int MillisecondsUntil(Clock::time_point deadline);

class Transport {
 public:
  virtual ~Transport() = default;
  // The next valid frame received before `deadline`, else nullopt. Refused input is counted in
  // `refused`. A UDP transport takes the sender of the first hello as its peer.
  virtual std::optional<Frame> Receive(Clock::time_point deadline, Refused& refused) = 0;
  // Sends one frame to the peer (UDP: the hello's sender).
  virtual Status Send(const std::vector<std::uint8_t>& frame) = 0;
  // Where the controller connects, e.g. "udp 127.0.0.1:40123" or "pty /dev/pts/5".
  virtual std::string Describe() const = 0;
};

// A UDP socket bound to `address`:`port` (port 0: one the system picks).
Result<std::unique_ptr<Transport>> OpenUdp(const std::string& address, int port);

// A pseudo-terminal in raw mode; `link` (if not empty) becomes a symbolic link to its slave
// device, removed when the transport closes.
Result<std::unique_ptr<Transport>> OpenPty(const std::string& link);

}  // namespace recruit::sil
