#include "drivers/transport/sp_serial.hpp"

#include <libserialport.h>

#include <cstdio>

namespace stipplot::io {

SpConfig to_sp_config(const SerialSettings& s) {
  SpConfig c{};
  c.baud = s.baud;
  c.bits = s.data_bits;
  c.stop_bits = s.stop_bits;
  c.parity = s.parity == Parity::Odd ? SP_PARITY_ODD : s.parity == Parity::Even ? SP_PARITY_EVEN : SP_PARITY_NONE;
  c.flowcontrol = s.flow == FlowControl::RtsCts    ? SP_FLOWCONTROL_RTSCTS
                  : s.flow == FlowControl::XonXoff ? SP_FLOWCONTROL_XONXOFF
                                                   : SP_FLOWCONTROL_NONE;
  return c;
}

static std::string sp_error_text() {
  char* m = sp_last_error_message();
  std::string s = m ? m : "unknown error";
  if (m) sp_free_error_message(m);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

SpSerial::SpSerial(std::string name, const SerialSettings& s) : name_(std::move(name)), settings_(s) {
  if (sp_get_port_by_name(name_.c_str(), &port_) != SP_OK) {
    port_ = nullptr;
    throw TransportError(TransportError::Kind::NotFound,
                         "no serial port named " + name_ + " (run `stipplot devices` to list ports)");
  }
  if (sp_open(port_, SP_MODE_READ_WRITE) != SP_OK) {
    std::string why = sp_error_text();
    sp_free_port(port_);
    port_ = nullptr;
    throw TransportError(TransportError::Kind::NotFound, "cannot open serial port " + name_ + ": " + why);
  }
  SpConfig c = to_sp_config(s);
  if (sp_set_baudrate(port_, c.baud) != SP_OK || sp_set_bits(port_, c.bits) != SP_OK ||
      sp_set_parity(port_, static_cast<sp_parity>(c.parity)) != SP_OK ||
      sp_set_stopbits(port_, c.stop_bits) != SP_OK ||
      sp_set_flowcontrol(port_, static_cast<sp_flowcontrol>(c.flowcontrol)) != SP_OK) {
    std::string why = sp_error_text();
    close();
    throw TransportError(TransportError::Kind::Io, "cannot configure " + name_ + ": " + why);
  }
}

SpSerial::~SpSerial() { close(); }

void SpSerial::close() {
  if (!port_) return;
  sp_close(port_);
  sp_free_port(port_);
  port_ = nullptr;
}

std::string SpSerial::describe() const {
  return "serial " + name_ + " @" + std::to_string(settings_.baud) + " (libserialport, flow " +
         to_string(settings_.flow) + ")";
}

void SpSerial::fail(const char* what, int rc) {
  std::string why = rc == SP_ERR_FAIL ? sp_error_text() : "libserialport code " + std::to_string(rc);
  close();
  throw TransportError(TransportError::Kind::Disconnected,
                       "serial port " + name_ + " disconnected during " + what + " (" + why + ")");
}

void SpSerial::write(std::string_view bytes, Millis timeout) {
  if (!port_) throw TransportError(TransportError::Kind::Disconnected, "serial port " + name_ + " is closed");
  sp_return rc = sp_blocking_write(port_, bytes.data(), bytes.size(), static_cast<unsigned>(timeout.count()));
  if (rc < 0) fail("write", rc);
  if (static_cast<size_t>(rc) < bytes.size())
    throw TransportError(TransportError::Kind::Timeout, "serial port " + name_ + " did not accept data for " +
                                                            std::to_string(timeout.count()) + " ms");
}

size_t SpSerial::read(char* buf, size_t n, Millis timeout) {
  if (!port_) throw TransportError(TransportError::Kind::Disconnected, "serial port " + name_ + " is closed");
  // Wait for the first byte, then take whatever else is already there.
  // (libserialport reads a timeout of 0 as "wait forever".)
  sp_return rc = timeout.count() <= 0 ? sp_nonblocking_read(port_, buf, n)
                                      : sp_blocking_read_next(port_, buf, n, static_cast<unsigned>(timeout.count()));
  if (rc < 0) fail("read", rc);
  return static_cast<size_t>(rc);
}

void SpSerial::flush() {
  if (port_) sp_drain(port_);
}

std::vector<SerialPortInfo> list_serial_ports() {
  std::vector<SerialPortInfo> out;
  sp_port** list = nullptr;
  if (sp_list_ports(&list) != SP_OK) return out;
  for (sp_port** p = list; p && *p; ++p) {
    SerialPortInfo i;
    auto str = [](const char* s) { return s ? std::string(s) : std::string(); };
    i.name = str(sp_get_port_name(*p));
    i.description = str(sp_get_port_description(*p));
    switch (sp_get_port_transport(*p)) {
      case SP_TRANSPORT_USB: {
        i.transport = "usb";
        int vid = -1, pid = -1;
        if (sp_get_port_usb_vid_pid(*p, &vid, &pid) == SP_OK) {
          i.vid = vid;
          i.pid = pid;
        }
        i.manufacturer = str(sp_get_port_usb_manufacturer(*p));
        i.product = str(sp_get_port_usb_product(*p));
        i.serial = str(sp_get_port_usb_serial(*p));
        break;
      }
      case SP_TRANSPORT_BLUETOOTH: i.transport = "bluetooth"; break;
      default: i.transport = "native"; break;
    }
    out.push_back(std::move(i));
  }
  sp_free_port_list(list);
  return out;
}

}  // namespace stipplot::io
