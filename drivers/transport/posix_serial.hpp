#pragma once
// Serial port on plain POSIX termios: raw mode, baud, parity, XON/XOFF or RTS/CTS set
// through termios. Works on pseudo-terminals (the simulator), which libserialport
// cannot open, and is the fallback for hardware ports.
#include <chrono>
#include <string>

#include "drivers/transport/transport.hpp"

namespace stipplot::io {

class PosixSerial final : public Transport {
 public:
  // Throws TransportError(NotFound) if the path cannot be opened.
  PosixSerial(std::string path, const SerialSettings& s);
  ~PosixSerial() override;
  void write(std::string_view bytes, Millis timeout) override;
  size_t read(char* buf, size_t n, Millis timeout) override;
  void flush() override;
  bool is_connected() const override { return fd_ >= 0; }
  void close() override;
  std::string describe() const override;
  // A pty has no baud rate; pacing writes to `bytes_per_s` makes it behave like a
  // UART (so in-band XON/XOFF arrives before the host has queued kilobytes).
  void pace(double bytes_per_s) { pace_bps_ = bytes_per_s; }
  int fd() const { return fd_; }

 private:
  [[noreturn]] void fail_disconnected(const char* what, int err);
  std::string path_;
  SerialSettings settings_;
  int fd_ = -1;
  double pace_bps_ = 0;
  std::chrono::steady_clock::time_point pace_next_{};
};

// termios speed constant for a baud rate; throws UserError for rates termios lacks.
unsigned baud_to_speed(int baud);

}  // namespace stipplot::io
