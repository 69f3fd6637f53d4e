#include "cli/commands.hpp"

namespace stipplot::cli {

void register_all(CLI::App& app) {
  register_stipple(app);
  register_eval(app);
  register_tree(app);
  register_sketch(app);
  register_pointillism(app);
  register_profiles(app);
  register_export(app);
  register_devices(app);
  register_sim(app);
  register_plot(app);
  register_serve(app);
}

}  // namespace stipplot::cli
