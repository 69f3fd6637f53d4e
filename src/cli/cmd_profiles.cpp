// stipplot profiles: the shipped device profiles, one a line, name first.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "drivers/device/profile.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

void register_profiles(CLI::App& app) {
  struct Args {
    bool json = false;
    std::string show;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("profiles", "List the device profiles (plotters) that export and plot know");
  cmd->footer(
      "Profiles are TOML files found in $STIPPLOT_PROFILES, a profiles/ folder next to the executable,\n"
      "or the source tree's drivers/profiles. Any file can be given as --profile PATH.\n"
      "Example: stipplot profiles   |   stipplot profiles --show hp7475a-a4");
  cmd->add_flag("--json", args->json, "One JSON line: name, description, protocol, travel, pens, file");
  cmd->add_option("--show", args->show, "Print the named profile's file (NAME or PATH)");
  cmd->callback([args] {
    if (!args->show.empty()) {
      DeviceProfile p = find_profile(args->show);
      std::FILE* f = std::fopen(p.source.c_str(), "rb");
      if (!f) throw UserError("cannot read " + p.source.string());
      char buf[4096];
      size_t n;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) std::fwrite(buf, 1, n, stdout);
      std::fclose(f);
      return;
    }
    auto all = list_profiles();
    if (args->json) {
      nlohmann::json j = nlohmann::json::array();
      for (const auto& p : all)
        j.push_back({{"name", p.name},
                     {"description", p.description},
                     {"protocol", to_string(p.protocol)},
                     {"pen_method", pen_method_name(p.pen)},
                     {"travel_mm", {p.machine.travel_x_mm, p.machine.travel_y_mm}},
                     {"pens", p.pen.count},
                     {"file", p.source.string()}});
      std::printf("%s\n", j.dump().c_str());
      return;
    }
    if (all.empty()) throw UserError("no device profiles found (set STIPPLOT_PROFILES to a folder of .toml files)");
    size_t width = 0;
    for (const auto& p : all) width = std::max(width, p.name.size());
    for (const auto& p : all) std::printf("%-*s  %s\n", static_cast<int>(width), p.name.c_str(), p.description.c_str());
  });
}

}  // namespace stipplot::cli
