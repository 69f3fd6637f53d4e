// stipplot devices: serial ports (with USB ids) and USB devices a plotter could be on.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "drivers/transport/devices.hpp"

namespace stipplot::cli {

void register_devices(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("devices", "List serial ports and USB devices a plotter could be connected to");
  cmd->footer(
      "Serial ports come from libserialport (with USB VID:PID and product), USB devices from libusb.\n"
      "`stipplot plot` without --port uses the one plausible device, if there is exactly one.\n"
      "Example: stipplot devices --json");
  cmd->add_flag("--json", *json, "One-line JSON output");
  cmd->callback([json] {
    io::DeviceList d = io::list_devices();
    if (*json) {
      nlohmann::json j;
      j["serial"] = nlohmann::json::array();
      for (const auto& p : d.serial)
        j["serial"].push_back({{"port", p.name}, {"transport", p.transport}, {"description", p.description},
                               {"vid", p.vid}, {"pid", p.pid}, {"manufacturer", p.manufacturer},
                               {"product", p.product}, {"serial", p.serial}});
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
