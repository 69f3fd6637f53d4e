#include "drivers/transport/posix_serial.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

namespace stipplot::io {

unsigned baud_to_speed(int baud) {
  switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 2000000: return B2000000;
    default: break;
  }
  throw UserError("baud rate " + std::to_string(baud) +
                  " is not supported by termios (use 1200..2000000 standard rates)");
}

PosixSerial::PosixSerial(std::string path, const SerialSettings& s) : path_(std::move(path)), settings_(s) {
  unsigned speed = baud_to_speed(s.baud);
  fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0)
    throw TransportError(TransportError::Kind::NotFound,
                         "cannot open serial port " + path_ + ": " + std::strerror(errno));
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) {
    int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw TransportError(TransportError::Kind::Io, path_ + " is not a serial port: " + std::strerror(e));
  }
  ::cfmakeraw(&tio);
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE);
  tio.c_cflag |= s.data_bits == 7 ? CS7 : CS8;
  if (s.parity == Parity::None) tio.c_cflag &= ~static_cast<tcflag_t>(PARENB);
  else {
    tio.c_cflag |= PARENB;
    if (s.parity == Parity::Odd) tio.c_cflag |= PARODD;
    else tio.c_cflag &= ~static_cast<tcflag_t>(PARODD);
  }
  if (s.stop_bits == 2) tio.c_cflag |= CSTOPB;
  else tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB);
  tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS);
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  if (s.flow == FlowControl::RtsCts) tio.c_cflag |= CRTSCTS;
  if (s.flow == FlowControl::XonXoff) tio.c_iflag |= IXON | IXOFF;
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
    int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw TransportError(TransportError::Kind::Io, "cannot configure " + path_ + ": " + std::strerror(e));
  }
}

PosixSerial::~PosixSerial() { close(); }

void PosixSerial::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::string PosixSerial::describe() const {
  return "serial " + path_ + " @" + std::to_string(settings_.baud) + " (termios, flow " +
         to_string(settings_.flow) + ")";
}

void PosixSerial::fail_disconnected(const char* what, int err) {
  close();
  throw TransportError(TransportError::Kind::Disconnected,
                       "serial port " + path_ + " disconnected (" + what + (err ? std::string(": ") + std::strerror(err) : "") + ")");
}

void PosixSerial::write(std::string_view bytes, Millis timeout) {
  if (fd_ < 0) throw TransportError(TransportError::Kind::Disconnected, "serial port " + path_ + " is closed");
  using clock = std::chrono::steady_clock;
  auto deadline = clock::now() + timeout;
  size_t off = 0;
  while (off < bytes.size()) {
    size_t chunk = bytes.size() - off;
    if (pace_bps_ > 0) {
      // A 16-byte FIFO may run ahead of the wire; beyond that, wait for byte time.
      chunk = std::min<size_t>(chunk, 16);
      auto now = clock::now();
      if (pace_next_ < now) pace_next_ = now;
      auto fifo = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(16 / pace_bps_));
      if (pace_next_ - fifo > now) std::this_thread::sleep_until(pace_next_ - fifo);
    }
    ssize_t w = ::write(fd_, bytes.data() + off, chunk);
    if (w > 0) {
      off += static_cast<size_t>(w);
      if (pace_bps_ > 0)
        pace_next_ += std::chrono::duration_cast<clock::duration>(
            std::chrono::duration<double>(static_cast<double>(w) / pace_bps_));
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK) fail_disconnected("write", errno);
    auto left = std::chrono::duration_cast<Millis>(deadline - clock::now()).count();
    if (left <= 0)
      throw TransportError(TransportError::Kind::Timeout,
                           "serial port " + path_ + " did not accept data for " +
                               std::to_string(timeout.count()) + " ms (flow control holding?)");
    pollfd p{fd_, POLLOUT, 0};
    int r = ::poll(&p, 1, static_cast<int>(std::min<long>(left, 100)));
    if (r > 0 && (p.revents & (POLLHUP | POLLERR)) && !(p.revents & POLLOUT)) fail_disconnected("hang-up", 0);
  }
}

size_t PosixSerial::read(char* buf, size_t n, Millis timeout) {
  if (fd_ < 0) throw TransportError(TransportError::Kind::Disconnected, "serial port " + path_ + " is closed");
  pollfd p{fd_, POLLIN, 0};
  int r;
  do {
    r = ::poll(&p, 1, static_cast<int>(timeout.count()));
  } while (r < 0 && errno == EINTR);
  if (r < 0) fail_disconnected("poll", errno);
  if (r == 0) return 0;
  ssize_t got = ::read(fd_, buf, n);
  if (got > 0) return static_cast<size_t>(got);
  if (got < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
  fail_disconnected(got == 0 ? "end of file" : "read", got == 0 ? 0 : errno);
}

void PosixSerial::flush() {
  if (fd_ >= 0) ::tcdrain(fd_);
}

}  // namespace stipplot::io
