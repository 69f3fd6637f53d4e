#pragma once
#include <CLI/CLI.hpp>

namespace stipplot::cli {
// Each adds one subcommand to the app.
void register_stipple(CLI::App& app);
void register_eval(CLI::App& app);
void register_tree(CLI::App& app);
void register_sketch(CLI::App& app);
void register_pointillism(CLI::App& app);
void register_hatch(CLI::App& app);
void register_profiles(CLI::App& app);
void register_export(CLI::App& app);
void register_devices(CLI::App& app);
void register_sim(CLI::App& app);
void register_plot(CLI::App& app);
void register_pen(CLI::App& app);
void register_serve(CLI::App& app);
void register_help_export(CLI::App& app);  // hidden: docs and completions from the options
void register_all(CLI::App& app);
}  // namespace stipplot::cli
