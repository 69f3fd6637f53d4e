// stipplot serve: the local web studio (src/serve) over this program's own commands.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/transport/devices.hpp"
#include "serve/child.hpp"
#include "serve/option_schema.hpp"
#include "serve/studio.hpp"
#include "util/error.hpp"
#include "util/executable.hpp"

namespace stipplot::cli {

namespace {

struct ServeArgs {
  int port = 8080;
  std::string bind = "127.0.0.1";
  std::string token;
  uint64_t max_pixels = 50'000'000;
  double max_upload_mb = 64;
  double sim_speedup = 20;
};

// The drawing methods' options as the page's controls: everything but what the studio
// decides itself (the files it writes, the report format, the input limit) and the
// device-sheet layout, which the studio leaves at the profile's.
nlohmann::json method_schemas() {
  CLI::App app;
  register_all(app);
  nlohmann::json methods = nlohmann::json::object();
  for (const char* name : {"stipple", "tree", "sketch", "pointillism", "hatch"}) {
    const CLI::App* sub = app.get_subcommand(name);
    std::set<std::string> skip = {"--json", "--quiet", "--max-pixels", "--threads", "--help"};
    for (const CLI::Option* o : sub->get_options()) {
      const bool output = o->get_group() == "Output" && !o->check_lname("profile");
      if (!output && o->get_group() != "Layout") continue;
      for (const auto& l : o->get_lnames()) skip.insert("--" + l);
    }
    methods[name] = {{"description", sub->get_description()}, {"options", serve::option_schema(*sub, skip)}};
  }
  return methods;
}

nlohmann::json profile_list() {
  nlohmann::json out = nlohmann::json::array();
  for (const DeviceProfile& p : list_profiles()) {
    out.push_back({{"name", p.name},
                   {"description", p.description},
                   {"dialect", p.protocol == Protocol::grbl ? "gcode" : p.protocol == Protocol::ebb ? "ebb" : "hpgl"}});
  }
  return out;
}

void serve(const ServeArgs& a) {
  if (a.port < 0 || a.port > 65535) throw UserError("--port must be 0..65535");
  if (a.max_pixels == 0) throw UserError("--max-pixels must be at least 1");
  if (!(a.max_upload_mb > 0)) throw UserError("--max-upload-mb must be positive");
  serve::StudioConfig c;
  c.guard.bind = a.bind;
  c.guard.port = a.port;
  c.guard.token = a.token;
  const bool local = serve::is_loopback_address(a.bind);
  // Anyone on the network could move the machine: another bind needs a token.
  if (!local && c.guard.token.empty()) c.guard.token = serve::random_token();
  c.workdir = std::filesystem::current_path();
  c.executable = self_executable();
  c.methods = method_schemas();
  c.profiles = profile_list();
  c.max_pixels = a.max_pixels;
  c.max_upload_bytes = static_cast<uint64_t>(a.max_upload_mb * 1024 * 1024);
  c.sim_speedup = a.sim_speedup;
  c.list_ports = [] { return io::plausible_ports(io::list_devices()); };
  serve::Studio studio(c);
  if (!studio.bind()) throw UserError("cannot listen on " + a.bind + ":" + std::to_string(a.port) + " (in use? try --port)");
  const std::string host = a.bind.find(':') != std::string::npos ? "[" + a.bind + "]" : a.bind;
  std::string url = "http://" + (a.bind == "0.0.0.0" ? std::string("127.0.0.1") : host) + ":" + std::to_string(studio.port()) + "/";
  if (!c.guard.token.empty()) url += "?token=" + c.guard.token;
  std::printf("stipplot studio: open %s\n(working folder %s; Ctrl-C stops)\n", url.c_str(), c.workdir.c_str());
  std::fflush(stdout);
  studio.run();
}

}  // namespace

void register_serve(CLI::App& app) {
  auto a = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand("serve", "Open the studio: photo in, live preview, plot from the browser");
  cmd->footer(
      "Serves one page on 127.0.0.1. Another --bind needs a token: give --token or one is made and\n"
      "printed in the address to open. Uploads, drawings and jobs stay in the current folder.\n"
      "Example: stipplot serve --port 8080");
  cmd->add_option("--port", a->port, "TCP port (0 = any free one)")->capture_default_str();
  cmd->add_option("--bind", a->bind, "Address to listen on")->capture_default_str();
  cmd->add_option("--token", a->token, "Secret every request must carry (required off 127.0.0.1; made when not given)");
  cmd->add_option("--max-pixels", a->max_pixels, "Refuse uploaded photos with more pixels than this")->capture_default_str();
  cmd->add_option("--max-upload-mb", a->max_upload_mb, "Refuse uploads larger than this")->capture_default_str();
  cmd->add_option("--sim-speedup", a->sim_speedup, "The built-in simulator runs this many times faster than the plotter")
      ->capture_default_str();
  cmd->callback([a] { serve(*a); });
}

}  // namespace stipplot::cli
