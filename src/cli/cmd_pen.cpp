// stipplot pen: an AxiDraw-class (EiBotBoard) plotter's pen heights set and tried before a
// plot, as axicli's setup and toggle modes do: the servo's up and down positions in percent
// of its range (the profile's unless given), then the pen raised, lowered, toggled or
// cycled (down, then up). Jobs carry their own servo settings; this only sets up the board.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/pen_heights.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/stream/ebb/nickname.hpp"
#include "drivers/stream/ebb/streamer.hpp"
#include "drivers/transport/devices.hpp"
#include "drivers/transport/transport.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {

struct PenArgs {
  std::string action;
  std::string profile = "axidraw-v3";
  std::string port;
  PenHeightArgs heights;
  bool json = false;
};

void run_pen(const PenArgs& a) {
  a.heights.check();
  DeviceProfile prof = find_profile(a.profile);
  if (prof.protocol != Protocol::ebb)
    throw UserError("pen: --profile " + prof.name +
                    " is not an EiBotBoard plotter (a grbl or HPGL plotter's pen is set in its profile)");
  a.heights.apply(prof);
  const EbbPen pen = ebb_pen(prof.pen, prof.ebb);
  const std::string port_name =
      io::ebb::resolve_port(a.port.empty() ? io::choose_port(io::list_devices()) : a.port, prof.serial.port);
  auto port = io::open_port(port_name, prof.serial.port);
  io::ebb::Streamer st(*port, io::ebb::options_for(prof));
  st.connect();
  for (const std::string& c : ebb_servo_setup(pen)) st.command(c);
  const std::string raise = ebb_pen_command(pen, false), lower = ebb_pen_command(pen, true);
  if (a.action == "up") {
    st.command(raise);
  } else if (a.action == "down") {
    st.command(lower);
  } else if (a.action == "toggle") {
    st.command(st.pen_up() ? lower : raise);
  } else {  // cycle: down, then up, to see both heights
    st.command(lower);
    st.command(raise);
  }
  st.wait_idle(10);
  const bool up = st.pen_up();
  if (a.json) {
    nlohmann::json j{{"command", "pen"},          {"action", a.action},        {"port", port_name},
                     {"profile", prof.name},      {"firmware", st.firmware().text}, {"pen", up ? "up" : "down"},
                     {"pos_up_pct", prof.pen.pos_up_pct}, {"pos_down_pct", prof.pen.pos_down_pct},
                     {"servo_up", pen.up},        {"servo_down", pen.down}};
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("pen %s on %s (%s): up at %g %% of the servo's range (pulse %d), down at %g %% (pulse %d)\n",
                up ? "up" : "down", port_name.c_str(), prof.name.c_str(), prof.pen.pos_up_pct, pen.up,
                prof.pen.pos_down_pct, pen.down);
  }
}

}  // namespace

void register_pen(CLI::App& app) {
  auto a = std::make_shared<PenArgs>();
  CLI::App* cmd = app.add_subcommand(
      "pen", "Set an AxiDraw-class (EiBotBoard) plotter's pen heights and raise, lower, toggle or cycle the pen");
  cmd->footer(
      "Heights are percent of the servo's range, as axicli's pen_pos_up and pen_pos_down (the profile's\n"
      "unless given). A job keeps its own settings: give plot and export the same --pos-up/--pos-down,\n"
      "or put them in a profile of your own (pos_up_pct, pos_down_pct). Without --port the one\n"
      "plausible device is used.\n"
      "Examples: stipplot pen cycle --pos-down 25            (lower to 25 %, raise to the profile's 60 %)\n"
      "          stipplot pen toggle --port /dev/ttyACM0 --profile axidraw-v3-a3");
  cmd->add_option("action", a->action, "up | down | toggle | cycle (down, then up)")
      ->required()
      ->check(CLI::IsMember({"up", "down", "toggle", "cycle"}));
  cmd->add_option("--profile", a->profile, "EBB device profile NAME or PATH (see `stipplot profiles`)")->capture_default_str();
  cmd->add_option("--port", a->port, "Serial port of the board, or ebb:NAME (its nickname; default: the one plausible device)");
  add_pen_height_options(cmd, a->heights);
  cmd->add_flag("--json", a->json, "One-line JSON output");
  cmd->callback([a] { run_pen(*a); });
}

}  // namespace stipplot::cli
