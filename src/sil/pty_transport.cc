// A pseudo-terminal in raw mode: the controller opens its slave device as it would a USB serial
// port; frames travel as a byte stream (StreamDeframer).
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <thread>

#include "sil/transport.h"

namespace recruit::sil {
namespace {

class PtyTransport : public Transport {
 public:
  PtyTransport(int master, int slave, std::string path, std::string link)
      : master_(master), slave_(slave), path_(std::move(path)), link_(std::move(link)) {}
  ~PtyTransport() override {
    // Closing the master hangs the slave up, which may discard what the controller has not read
    // yet (the end frame): give it a moment.
    ::tcdrain(master_);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!link_.empty()) {
      std::error_code ec;
      std::filesystem::remove(link_, ec);
    }
    ::close(slave_);
    ::close(master_);
  }

  std::optional<Frame> Receive(Clock::time_point deadline, Refused& refused) override {
    std::uint8_t buf[512];
    for (;;) {
      const long frames = deframer_.dropped_frames(), bytes = deframer_.dropped_bytes();
      std::optional<Frame> f = deframer_.Next();
      refused.malformed += deframer_.dropped_frames() - frames;
      refused.junk_bytes += deframer_.dropped_bytes() - bytes;
      if (f) return f;
      pollfd p{master_, POLLIN, 0};
      const int r = ::poll(&p, 1, MillisecondsUntil(deadline));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) return std::nullopt;
      const ssize_t n = ::read(master_, buf, sizeof buf);
      if (n > 0) {
        deframer_.Append(buf, static_cast<std::size_t>(n));
      } else if (Clock::now() >= deadline) {
        return std::nullopt;
      }
    }
  }

  Status Send(const std::vector<std::uint8_t>& frame) override {
    std::size_t done = 0;
    while (done < frame.size()) {
      const ssize_t n = ::write(master_, frame.data() + done, frame.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return IoError(std::string("pty: cannot write: ") + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
    return Status::Ok();
  }

  std::string Describe() const override {
    return "pty " + (link_.empty() ? path_ : link_ + " -> " + path_);
  }

 private:
  int master_, slave_;
  std::string path_, link_;
  StreamDeframer deframer_;
};

}  // namespace

Result<std::unique_ptr<Transport>> OpenPty(const std::string& link) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) {
    const std::string why = std::strerror(errno);
    if (master >= 0) ::close(master);
    return IoError("pty: cannot create a pseudo-terminal: " + why);
  }
  const char* name = ::ptsname(master);
  const std::string path = name != nullptr ? name : "";
  // The plant keeps the slave open itself, so that the master neither hangs up nor fails with
  // EIO while the controller has it closed (before it connects, between reopenings).
  const int slave = path.empty() ? -1 : ::open(path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave < 0) {
    ::close(master);
    return IoError("pty: cannot open its slave device '" + path + "'");
  }
  termios t{};
  ::tcgetattr(slave, &t);
  ::cfmakeraw(&t);  // bytes as sent: no echo, no line editing, no CR/LF translation
  ::tcsetattr(slave, TCSANOW, &t);
  if (!link.empty()) {
    std::error_code ec;
    if (std::filesystem::is_symlink(link, ec)) std::filesystem::remove(link, ec);
    std::filesystem::create_symlink(path, link, ec);
    if (ec) {
      ::close(slave);
      ::close(master);
      return IoError("pty: cannot create the link '" + link + "': " + ec.message());
    }
  }
  return std::unique_ptr<Transport>(new PtyTransport(master, slave, path, link));
}

}  // namespace recruit::sil
