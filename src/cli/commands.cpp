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
}

}  // namespace stipplot::cli
