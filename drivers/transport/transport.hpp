#pragma once
// One interface for every way bytes reach a plotter: a serial port (termios or
// libserialport), a USB bulk endpoint (libusb), a file, or the in-process simulator.
// Everything above it (protocols, journal, progress) is the same code whichever
// back end carries the bytes.
#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "util/error.hpp"

namespace stipplot::io {

using Millis = std::chrono::milliseconds;

// A transport failure the user can act on (the CLI prints it as one line).
class TransportError : public UserError {
 public:
  enum class Kind { Io, Disconnected, Timeout, NotFound };
  TransportError(Kind kind, const std::string& msg) : UserError(msg), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

enum class FlowControl { None, XonXoff, RtsCts };
enum class Parity { None, Odd, Even };

struct SerialSettings {
  int baud = 115200;
  int data_bits = 8;
  Parity parity = Parity::None;
  int stop_bits = 1;
  FlowControl flow = FlowControl::None;
};
FlowControl parse_flow_control(const std::string& s);  // "none" | "xonxoff" | "rtscts"
const char* to_string(FlowControl f);

class Transport {
 public:
  virtual ~Transport() = default;
  // Writes all of `bytes`; throws TransportError (Timeout if the device does not take
  // them within `timeout`, Disconnected if it went away).
  virtual void write(std::string_view bytes, Millis timeout = Millis(10000)) = 0;
  // Reads what is available, waiting at most `timeout` for the first byte. Returns 0
  // on timeout (not an error: protocols decide how long silence may last); throws
  // TransportError(Disconnected) when the device has gone.
  virtual size_t read(char* buf, size_t n, Millis timeout) = 0;
  // Waits until written bytes have left the host (best effort).
  virtual void flush() {}
  virtual bool is_connected() const = 0;
  virtual void close() = 0;
  // "serial /dev/ttyUSB0 @115200", "usb 1a86:7523", ... for messages.
  virtual std::string describe() const = 0;
  // False for a write-only sink (a file, a USB printer node): nothing ever answers, so a
  // job goes to it raw, with no queries, handshakes or journal.
  virtual bool answers() const { return true; }
};

// Reads '\n'-terminated lines (a '\r' before it is dropped) from a transport.
class LineReader {
 public:
  explicit LineReader(Transport& t) : t_(t) {}
  // Next complete line, or false when none arrived within `timeout`.
  bool read_line(std::string& line, Millis timeout);
  // Like read_line but throws TransportError(Timeout) with `what` in the message.
  std::string expect_line(Millis timeout, const std::string& what);
  // Bytes received that are not part of a complete line yet.
  const std::string& pending() const { return buf_; }
  // Raw bytes, including any already buffered (for byte-oriented protocols).
  size_t read_raw(char* out, size_t n, Millis timeout);
  void clear() { buf_.clear(); }

 private:
  bool pop_line(std::string& line);
  Transport& t_;
  std::string buf_;
};

// Opens a transport from a port name: "/dev/ttyUSB0", "COM3" (serial: libserialport
// for hardware ports, termios for ptys and as fallback), "usb:VID:PID[:N]" (libusb
// bulk), "file:PATH" and USB printer-class nodes "/dev/usb/lpN" (write-only sinks).
std::unique_ptr<Transport> open_port(const std::string& port, const SerialSettings& s);

}  // namespace stipplot::io
