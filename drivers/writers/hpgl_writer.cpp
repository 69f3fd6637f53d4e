#include "drivers/writers/hpgl_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "drivers/device/carousel.hpp"
#include "drivers/device/machine.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

void append_xy(std::string& out, Steps s) {
  char buf[48];
  int n = std::snprintf(buf, sizeof buf, "%lld,%lld", static_cast<long long>(s.x), static_cast<long long>(s.y));
  out.append(buf, static_cast<size_t>(n));
}

void check_protocol(const Plan& plan, const DeviceProfile& profile) {
  if (profile.protocol != Protocol::hpgl)
    throw UserError("profile " + profile.name + " speaks " + to_string(profile.protocol) + ", not HPGL; write .gcode");
  check_plan_fits(plan, profile);
}

}  // namespace

void write_hpgl(const Plan& plan, const DeviceProfile& profile, const LineSink& sink) {
  check_protocol(plan, profile);
  MachineTransform t(profile, plan.page);
  const size_t chunk = static_cast<size_t>(std::max(1, profile.hpgl.max_points_per_command));
  sink("IN;");
  if (profile.hpgl.velocity) {
    // VS is in cm/s; the plotter uses it for pen-down moves.
    double v = std::min(profile.motion.speed_down_mm_s / 10.0, profile.hpgl.max_velocity_cm_s);
    char buf[32];
    std::snprintf(buf, sizeof buf, "VS%.1f;", v);
    std::string vs = buf;
    if (vs.size() > 4 && vs.compare(vs.size() - 3, 3, ".0;") == 0) vs.replace(vs.size() - 3, 3, ";");
    sink(vs);
  }
  std::string cmd;
  const std::vector<PenSlot> slots = plan_pen_slots(plan, profile.pen);
  for (size_t li = 0; li < plan.layers.size(); ++li) {
    if (!slots[li].reload.empty()) {
      // Stow the pen, then the pause the streamer stops at (hpgl_reader.hpp).
      sink("SP0;");
      sink(io::hpgl_pause_instruction(reload_message(slots[li].reload)));
    }
    sink("SP" + std::to_string(slots[li].slot) + ";");
    for (const auto& s : plan.layers[li].strokes) {
      if (s.pts.empty()) continue;
      Steps pos = t.to_steps(s.pts[0]);
      cmd = "PU";
      append_xy(cmd, pos);
      cmd += ';';
      sink(cmd);
      size_t in_cmd = 0;
      cmd = "PD";
      for (size_t i = 1; i < s.pts.size(); ++i) {
        Steps q = t.to_steps(s.pts[i]);
        if (q == pos) continue;  // shorter than a plotter unit
        if (in_cmd == chunk) {
          cmd += ';';
          sink(cmd);
          cmd = "PD";
          in_cmd = 0;
        }
        if (in_cmd) cmd += ',';
        append_xy(cmd, q);
        ++in_cmd;
        pos = q;
      }
      cmd += ';';
      sink(cmd);  // "PD;" alone: a pen touch where the pen is (a dot)
    }
    sink("PU;");
  }
  sink("SP0;");
}

std::vector<std::string> hpgl_commands(const Plan& plan, const DeviceProfile& profile) {
  std::vector<std::string> out;
  write_hpgl(plan, profile, [&](std::string_view l) { out.emplace_back(l); });
  return out;
}

void write_hpgl_file(const Plan& plan, const DeviceProfile& profile, const std::string& path) {
  check_protocol(plan, profile);  // before the file is created
  write_lines_atomic(
      path, [&](const LineSink& sink) { write_hpgl(plan, profile, sink); }, profile.serial.newline ? "\n" : "");
}

}  // namespace stipplot
