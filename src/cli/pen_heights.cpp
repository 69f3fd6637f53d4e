#include "cli/pen_heights.hpp"

#include "util/error.hpp"

namespace stipplot::cli {

namespace {
bool given(const CLI::Option* o) { return o && o->count() > 0; }
}  // namespace

bool PenHeightArgs::any_given() const { return given(up_opt) || given(down_opt); }

void PenHeightArgs::check() const {
  for (const auto& [opt, name, v] : {std::tuple{up_opt, "--pos-up", up}, std::tuple{down_opt, "--pos-down", down}})
    if (given(opt) && !(v >= 0 && v <= 100))  // NaN fails both
      throw UserError(std::string(name) + " must be a percentage of the servo's range, 0 to 100");
}

void PenHeightArgs::apply(DeviceProfile& p) const {
  if (given(moves_opt)) {
    if (p.protocol != Protocol::ebb)
      throw UserError("--ebb-moves sets how an EiBotBoard plotter's moves are written; profile " + p.name + " is not one (protocol " +
                      to_string(p.protocol) + ")");
    p.ebb.moves = moves == "sm" ? motion::EbbMoveKind::sm : motion::EbbMoveKind::lm;
  }
  if (!any_given()) return;
  check();
  if (p.protocol != Protocol::ebb)
    throw UserError(std::string(given(up_opt) ? "--pos-up" : "--pos-down") +
                    " sets an EiBotBoard plotter's pen servo; profile " + p.name +
                    " is not one (protocol " + to_string(p.protocol) + "; its pen is set in its profile)");
  set_ebb_pen_heights(p, given(up_opt) ? up : p.pen.pos_up_pct, given(down_opt) ? down : p.pen.pos_down_pct);
}

void add_pen_height_options(CLI::App* cmd, PenHeightArgs& a, const std::string& group) {
  a.up_opt = cmd->add_option("--pos-up", a.up, "EBB: pen-up height, percent of the servo's range (0-100; axicli pen_pos_up)");
  a.down_opt =
      cmd->add_option("--pos-down", a.down, "EBB: pen-down height, percent of the servo's range (0-100; axicli pen_pos_down)");
  if (!group.empty()) {
    a.up_opt->group(group);
    a.down_opt->group(group);
  }
}

void add_ebb_moves_option(CLI::App* cmd, PenHeightArgs& a, const std::string& group) {
  a.moves_opt = cmd->add_option("--ebb-moves", a.moves,
                                "EBB: the moves a job is written in: lm (the firmware's accelerating moves, 2.7+) or sm "
                                "(constant-rate slices, any firmware); the profile's [ebb] moves unless given")
                    ->check(CLI::IsMember({"lm", "sm"}));
  if (!group.empty()) a.moves_opt->group(group);
}

}  // namespace stipplot::cli
