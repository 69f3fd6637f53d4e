#pragma once
// What is plugged in: serial ports (libserialport, with USB ids) and USB devices with
// a bulk-OUT endpoint (libusb), and which one to use when no --port is given.
#include <map>
#include <string>
#include <vector>

#include "drivers/transport/sp_serial.hpp"
#include "drivers/transport/usb_bulk.hpp"

namespace stipplot::io {

struct DeviceList {
  std::vector<SerialPortInfo> serial;
  std::vector<UsbDeviceInfo> usb;
  std::string usb_error;  // why libusb could not look (empty when it could)
  // USB printer-class nodes the kernel's usblp driver made (/dev/usb/lpN): write-only
  // sinks, as many HPGL plotters and cutters present themselves.
  std::vector<std::string> printer_nodes;
  // EiBotBoards' nicknames by port, where they were asked (QT; drivers/stream/ebb/nickname.hpp).
  std::map<std::string, std::string> ebb_nicknames;
};
DeviceList list_devices();

// Port names a plotter could plausibly be on: USB serial adapters and ttyACM/ttyUSB
// ports, then USB devices with a bulk-OUT endpoint that are not one of those adapters
// (as usb:VID:PID). Built-in /dev/ttyS* ports are listed by `devices` but not chosen.
std::vector<std::string> plausible_ports(const DeviceList& d);

// Exactly one plausible port: its name. Otherwise throws UserError listing what was
// found (or saying nothing was), and how to pass --port.
std::string choose_port(const DeviceList& d);

// Human-readable listing for `stipplot devices`.
std::string format_devices(const DeviceList& d);

}  // namespace stipplot::io
