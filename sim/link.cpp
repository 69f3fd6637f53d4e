#include "sim/link.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>

#include "util/error.hpp"

namespace stipplot::sim {

PtyLink::PtyLink() {
  char name[256] = {};
  int slave = -1;
  if (::openpty(&master_, &slave, name, nullptr, nullptr) != 0)
    throw UserError(std::string("cannot open a pseudo-terminal: ") + std::strerror(errno));
  path_ = name;
  termios tio{};
  ::tcgetattr(slave, &tio);
  ::cfmakeraw(&tio);  // no echo, no line editing: a plain byte pipe until the driver sets its own modes
  ::tcsetattr(slave, TCSANOW, &tio);
  ::close(slave);
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  ::fcntl(master_, F_SETFD, FD_CLOEXEC);
}

bool PtyLink::client_present() {
  if (master_ < 0) return false;
  pollfd p{master_, 0, 0};
  ::poll(&p, 1, 0);
  return !(p.revents & POLLHUP);
}

PtyLink::~PtyLink() { close(); }

long PtyLink::read(char* buf, size_t n, double timeout_s) {
  if (master_ < 0) return -1;
  pollfd p{master_, POLLIN, 0};
  timespec ts{};
  if (timeout_s > 0) {
    ts.tv_sec = static_cast<time_t>(timeout_s);
    ts.tv_nsec = static_cast<long>((timeout_s - static_cast<double>(ts.tv_sec)) * 1e9);
  }
  int r = ::ppoll(&p, 1, &ts, nullptr);
  if (r > 0 && !(p.revents & POLLIN)) {  // hung up: nobody has the port open
    ::nanosleep(&ts, nullptr);
    return 0;
  }
  if (r <= 0) return 0;
  ssize_t got = ::read(master_, buf, n);
  if (got > 0) return got;
  return 0;  // EAGAIN / EIO while nobody has the slave open: just silence
}

void PtyLink::write(std::string_view bytes) {
  if (!client_present()) return;  // a pty keeps what nobody reads for the next opener; a wire does not
  size_t off = 0;
  int spins = 0;
  while (master_ >= 0 && off < bytes.size()) {
    ssize_t w = ::write(master_, bytes.data() + off, bytes.size() - off);
    if (w > 0) {
      off += static_cast<size_t>(w);
      continue;
    }
    if (w < 0 && (errno == EAGAIN || errno == EINTR) && ++spins < 2000) {
      pollfd p{master_, POLLOUT, 0};
      ::poll(&p, 1, 1);
      continue;
    }
    return;  // nobody reading: the bytes are lost, as on a real line
  }
}

// The slave's input queue, looked at through a second descriptor of our own.
size_t PtyLink::unread_by_client() {
  if (master_ < 0 || !client_present()) return 0;
  const int fd = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return 0;
  int n = 0;
  if (::ioctl(fd, FIONREAD, &n) != 0) n = 0;
  ::close(fd);
  return static_cast<size_t>(n);
}

void PtyLink::close() {
  if (master_ >= 0) ::close(master_);
  master_ = -1;
}

long PipeLink::read(char* buf, size_t n, double timeout_s) {
  auto us = std::chrono::microseconds(static_cast<long>(std::max(0.0, timeout_s) * 1e6));
  return end_->read(buf, n, us);
}

}  // namespace stipplot::sim
