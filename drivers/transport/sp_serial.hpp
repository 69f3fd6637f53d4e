#pragma once
// Serial port through libserialport, for hardware ports (USB-serial adapters, native
// UARTs). libserialport 0.1.1 cannot open a pseudo-terminal; PosixSerial serves those.
#include <string>
#include <vector>

#include "drivers/transport/transport.hpp"

struct sp_port;

namespace stipplot::io {

// Our settings as libserialport's enum values (a pure mapping, testable without hardware).
struct SpConfig {
  int baud, bits, parity, stop_bits, flowcontrol;  // sp_parity / sp_flowcontrol values
};
SpConfig to_sp_config(const SerialSettings& s);

class SpSerial final : public Transport {
 public:
  // Throws TransportError(NotFound) if libserialport does not know the port.
  SpSerial(std::string name, const SerialSettings& s);
  ~SpSerial() override;
  void write(std::string_view bytes, Millis timeout) override;
  size_t read(char* buf, size_t n, Millis timeout) override;
  void flush() override;
  bool is_connected() const override { return port_ != nullptr; }
  void close() override;
  std::string describe() const override;

 private:
  [[noreturn]] void fail(const char* what, int rc);
  std::string name_;
  SerialSettings settings_;
  sp_port* port_ = nullptr;
};

struct SerialPortInfo {
  std::string name;         // /dev/ttyUSB0
  std::string description;  // libserialport's description
  std::string transport;    // "usb", "native", "bluetooth"
  int vid = -1, pid = -1;   // USB ids when transport is usb
  std::string manufacturer, product, serial;
};
// Every serial port libserialport sees (empty when none). Never throws for "none".
std::vector<SerialPortInfo> list_serial_ports();

}  // namespace stipplot::io
