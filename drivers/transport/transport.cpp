#include "drivers/transport/transport.hpp"

#include <algorithm>
#include <cstring>

#include "drivers/transport/file_sink.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "drivers/transport/sp_serial.hpp"
#include "drivers/transport/usb_bulk.hpp"

namespace stipplot::io {

FlowControl parse_flow_control(const std::string& s) {
  if (s == "none") return FlowControl::None;
  if (s == "xonxoff" || s == "xon/xoff" || s == "software") return FlowControl::XonXoff;
  if (s == "rtscts" || s == "rts/cts" || s == "hardware") return FlowControl::RtsCts;
  throw UserError("flow control must be none, xonxoff or rtscts, got '" + s + "'");
}

const char* to_string(FlowControl f) {
  switch (f) {
    case FlowControl::XonXoff: return "xonxoff";
    case FlowControl::RtsCts: return "rtscts";
    default: return "none";
  }
}

// grbl ends lines with \r\n, HPGL devices with a bare \r: either ends a line, and the
// empty "lines" between them are skipped.
bool LineReader::pop_line(std::string& line) {
  for (;;) {
    auto nl = buf_.find_first_of("\r\n");
    if (nl == std::string::npos) return false;
    line.assign(buf_, 0, nl);
    buf_.erase(0, nl + 1);
    if (!line.empty()) return true;
  }
}

bool LineReader::read_line(std::string& line, Millis timeout) {
  if (pop_line(line)) return true;
  auto deadline = std::chrono::steady_clock::now() + timeout;
  char tmp[1024];
  for (;;) {
    auto left = std::chrono::duration_cast<Millis>(deadline - std::chrono::steady_clock::now());
    if (left.count() < 0) left = Millis(0);
    size_t n = t_.read(tmp, sizeof tmp, left);
    buf_.append(tmp, n);
    if (pop_line(line)) return true;
    if (left.count() == 0) return false;
  }
}

std::string LineReader::expect_line(Millis timeout, const std::string& what) {
  std::string line;
  if (!read_line(line, timeout))
    throw TransportError(TransportError::Kind::Timeout, "no " + what + " from " + t_.describe() + " within " +
                                                            std::to_string(timeout.count()) + " ms");
  return line;
}

size_t LineReader::read_raw(char* out, size_t n, Millis timeout) {
  if (!buf_.empty()) {
    size_t k = std::min(n, buf_.size());
    std::memcpy(out, buf_.data(), k);
    buf_.erase(0, k);
    return k;
  }
  return t_.read(out, n, timeout);
}

static bool is_pty_path(const std::string& p) { return p.rfind("/dev/pts/", 0) == 0 || p.rfind("/dev/pty", 0) == 0; }

std::unique_ptr<Transport> open_port(const std::string& port, const SerialSettings& s) {
  if (port.empty()) throw UserError("no port given");
  if (port.rfind("usb:", 0) == 0) return std::make_unique<UsbBulk>(parse_usb_selector(port));
  if (port.rfind("file:", 0) == 0) return std::make_unique<FileSink>(port.substr(5));
  // The kernel's usblp driver: many HPGL plotters and cutters present themselves so.
  if (port.rfind("/dev/usb/lp", 0) == 0) return std::make_unique<FileSink>(port);
  if (is_pty_path(port)) return std::make_unique<PosixSerial>(port, s);
  try {
    return std::make_unique<SpSerial>(port, s);
  } catch (const TransportError&) {
    // Not a port libserialport knows (a symlink, an unusual driver): plain termios.
    return std::make_unique<PosixSerial>(port, s);
  }
}

}  // namespace stipplot::io
