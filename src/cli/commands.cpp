#include "cli/commands.hpp"

namespace stipplot::cli {

void register_all(CLI::App& app) {
  register_stipple(app);
  register_eval(app);
  register_devices(app);
  register_sim(app);
  register_plot(app);
}

}  // namespace stipplot::cli
