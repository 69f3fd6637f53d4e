#include "drivers/transport/devices.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

namespace stipplot::io {

namespace {
std::string hexid(int vid, int pid) {
  char b[16];
  std::snprintf(b, sizeof b, "%04x:%04x", vid & 0xffff, pid & 0xffff);
  return b;
}
// Microchip's id for the EiBotBoard (AxiDraw, NextDraw, iDraw, EggBot): said, so the user
// knows which profiles fit.
std::string known_board(int vid, int pid) {
  return vid == 0x04d8 && pid == 0xfd92
             ? "  [EiBotBoard: AxiDraw, NextDraw, iDraw: --profile axidraw-v3|axidraw-v3-a3|axidraw-minikit|"
               "nextdraw-8511|nextdraw-1117|nextdraw-2234|idraw-a4|idraw-a3]"
             : "";
}
bool plausible_serial(const SerialPortInfo& p) {
  if (p.transport == "usb") return true;
  return p.name.find("ttyACM") != std::string::npos || p.name.find("ttyUSB") != std::string::npos;
}
}  // namespace

DeviceList list_devices() {
  DeviceList d;
  d.serial = list_serial_ports();
  d.usb = list_usb_devices(&d.usb_error);
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev/usb", ec))
    if (e.path().filename().string().rfind("lp", 0) == 0) d.printer_nodes.push_back(e.path().string());
  std::sort(d.printer_nodes.begin(), d.printer_nodes.end());
  return d;
}

std::vector<std::string> plausible_ports(const DeviceList& d) {
  std::vector<std::string> out;
  std::set<std::pair<int, int>> adapters;
  for (const auto& p : d.serial)
    if (plausible_serial(p)) {
      out.push_back(p.name);
      if (p.vid >= 0) adapters.insert({p.vid, p.pid});
    }
  for (const auto& u : d.usb)
    if (u.has_bulk_out && !adapters.count({u.vid, u.pid})) out.push_back("usb:" + hexid(u.vid, u.pid));
  for (const auto& n : d.printer_nodes) out.push_back(n);
  return out;
}

std::string choose_port(const DeviceList& d) {
  auto ports = plausible_ports(d);
  if (ports.size() == 1) return ports[0];
  if (ports.empty())
    throw UserError("no plotter found: no USB serial port or USB device is connected (try --sim to use the "
                    "simulated plotter, or give --port)");
  std::string list;
  for (const auto& p : ports) list += (list.empty() ? "" : ", ") + p;
  throw UserError("several possible plotters found (" + list + "): choose one with --port");
}

std::string format_devices(const DeviceList& d) {
  std::string s;
  char line[512];
  if (d.serial.empty()) s += "Serial ports: none found\n";
  else {
    s += "Serial ports:\n";
    for (const auto& p : d.serial) {
      const auto nick = d.ebb_nicknames.find(p.name);
      const std::string named = nick == d.ebb_nicknames.end() ? ""
                                : nick->second.empty()       ? "  (no nickname)"
                                                             : "  nickname '" + nick->second + "' (--port ebb:" + nick->second + ")";
      if (p.vid >= 0)
        std::snprintf(line, sizeof line, "  %-16s usb %s  %s %s%s%s\n", p.name.c_str(), hexid(p.vid, p.pid).c_str(),
                      p.manufacturer.c_str(), p.product.c_str(), named.c_str(), known_board(p.vid, p.pid).c_str());
      else
        std::snprintf(line, sizeof line, "  %-16s %s  %s\n", p.name.c_str(), p.transport.c_str(), p.description.c_str());
      s += line;
    }
  }
  if (!d.usb_error.empty()) s += "USB devices: cannot look (" + d.usb_error + ")\n";
  else if (d.usb.empty()) s += "USB devices: none found\n";
  else {
    s += "USB devices:\n";
    for (const auto& u : d.usb) {
      std::snprintf(line, sizeof line, "  usb:%s  bus %d addr %d  %s %s%s\n", hexid(u.vid, u.pid).c_str(), u.bus, u.address,
                    u.manufacturer.c_str(), u.product.c_str(), u.has_bulk_out ? "  [bulk out]" : "");
      s += line;
    }
  }
  if (!d.printer_nodes.empty()) {
    s += "USB printer nodes (write-only: the job is sent raw, nothing answers):\n";
    for (const auto& n : d.printer_nodes) s += "  " + n + "\n";
  }
  auto ports = plausible_ports(d);
  if (ports.empty()) s += "No plotter connected. Try the simulator: stipplot plot IN --profile P --sim\n";
  return s;
}

}  // namespace stipplot::io
