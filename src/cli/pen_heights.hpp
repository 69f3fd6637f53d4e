#pragma once
// --pos-up / --pos-down: an EiBotBoard plotter's pen heights for one run, in percent of the
// servo's range as axicli's pen_pos_up / pen_pos_down, over the profile's pos_up_pct /
// pos_down_pct (pen, plot and export); and --ebb-moves (plot and export), the profile's
// [ebb] moves for one run: "lm" (the firmware's accelerating moves) or "sm".
#include <CLI/CLI.hpp>
#include <string>

#include "drivers/device/profile.hpp"

namespace stipplot::cli {

struct PenHeightArgs {
  double up = 0, down = 0;
  CLI::Option* up_opt = nullptr;  // given or not: no value (NaN included) means "not given"
  CLI::Option* down_opt = nullptr;
  std::string moves;                // --ebb-moves: "lm" or "sm"
  CLI::Option* moves_opt = nullptr;
  bool any_given() const;  // a height
  // 0 to 100 each, else a UserError naming the option.
  void check() const;
  // The heights given, over the profile's (and the pen times that follow); a UserError for
  // a profile that is not an EiBotBoard's.
  void apply(DeviceProfile& p) const;
};
void add_pen_height_options(CLI::App* cmd, PenHeightArgs& a, const std::string& group = "");
// --ebb-moves, applied by PenHeightArgs::apply.
void add_ebb_moves_option(CLI::App* cmd, PenHeightArgs& a, const std::string& group = "");

}  // namespace stipplot::cli
