// stipplot devices: serial ports (with USB ids) and USB devices a plotter could be on.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "drivers/stream/ebb/nickname.hpp"
#include "drivers/transport/devices.hpp"

namespace stipplot::cli {

void register_devices(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("devices", "List serial ports and USB devices a plotter could be connected to");
  cmd->footer(
      "Serial ports come from libserialport (with USB VID:PID and product), USB devices from libusb.\n"
      "Each EiBotBoard (04d8:fd92) is asked its nickname (QT): plot and pen take --port ebb:NAME.\n"
      "`stipplot plot` without --port uses the one plausible device, if there is exactly one.\n"
      "Example: stipplot devices --json");
  cmd->add_flag("--json", *json, "One-line JSON output");
  cmd->callback([json] {
    io::DeviceList d = io::list_devices();
    d.ebb_nicknames = io::ebb::read_nicknames(io::ebb::ebb_ports(d), io::SerialSettings{});
    if (*json) {
      nlohmann::json j;
      j["serial"] = nlohmann::json::array();
      for (const auto& p : d.serial) {
        nlohmann::json e{{"port", p.name},       {"transport", p.transport},       {"description", p.description},
                         {"vid", p.vid},         {"pid", p.pid},                   {"manufacturer", p.manufacturer},
                         {"product", p.product}, {"serial", p.serial}};
        if (auto n = d.ebb_nicknames.find(p.name); n != d.ebb_nicknames.end()) e["ebb_nickname"] = n->second;
        j["serial"].push_back(e);
      }
      j["usb"] = nlohmann::json::array();
      for (const auto& u : d.usb)
        j["usb"].push_back({{"vid", u.vid}, {"pid", u.pid}, {"bus", u.bus}, {"address", u.address},
                            {"manufacturer", u.manufacturer}, {"product", u.product}, {"bulk_out", u.has_bulk_out}});
      j["printer_nodes"] = d.printer_nodes;
      if (!d.usb_error.empty()) j["usb_error"] = d.usb_error;
      j["plausible"] = io::plausible_ports(d);
      std::printf("%s\n", j.dump().c_str());
    } else {
      std::fputs(io::format_devices(d).c_str(), stdout);
    }
  });
}

}  // namespace stipplot::cli
