#include "drivers/writers/ebb_writer.hpp"

#include <cmath>

#include "drivers/device/machine.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/motion/ebb_motion.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

void check_ebb_protocol(const Plan& plan, const DeviceProfile& profile) {
  if (profile.protocol != Protocol::ebb)
    throw UserError("profile " + profile.name + " speaks " + to_string(profile.protocol) +
                    ", not the EiBotBoard's commands; write ." + (profile.protocol == Protocol::hpgl ? "hpgl" : "gcode"));
  check_plan_fits(plan, profile);
}

// Writes the job, keeping the motors' position and the job's millisecond clock.
class EbbJobWriter {
 public:
  EbbJobWriter(const Plan& plan, const DeviceProfile& p, const LineSink& sink)
      : plan_(plan), p_(p), sink_(sink), t_(p, plan.page), geo_{p.ebb.steps_per_mm}, pen_(ebb_pen(p.pen, p.ebb)) {}

  void header() {
    sink_("EM,1,1");  // 16x microstepping on both motors; the board counts steps from here
    for (const std::string& c : ebb_servo_setup(pen_)) sink_(c);
    pen(false);
  }

  void stroke(const Stroke& s) {
    std::vector<Vec2> pts;
    pts.reserve(s.pts.size());
    for (const Vec2& q : s.pts) pts.push_back(t_.to_machine_mm(q));
    travel(pts.front());
    pen(true);
    move(pts, p_.motion.speed_down_mm_s);
    if (pts.size() == 1 && p_.pen.dot_dwell_s > 0)
      sink_("SM," + std::to_string(std::max<long>(1, std::lround(p_.pen.dot_dwell_s * 1000))) + ",0,0");
    pen(false);
  }

  void travel(Vec2 to) { move({geo_.mm(at_), to}, p_.motion.speed_up_mm_s); }

  void pause(const std::string& note) { sink_(io::ebb_pause_line(note)); }

 private:
  void pen(bool down) { sink_(ebb_pen_command(pen_, down)); }

  // The polyline from rest to rest, timed by the planner's model and cut into LMs (a
  // phase of its speed ramps each) or SMs, as the profile's [ebb] moves says.
  void move(const std::vector<Vec2>& pts, double vmax) {
    if (pts.size() < 2) return;
    moves_.clear();
    motion::polyline_moves(pts, vmax, p_.motion, geo_, {p_.ebb.moves, p_.ebb.time_slice_ms}, at_, clock_ticks_, blocks_,
                           moves_);
    for (const motion::EbbMove& m : moves_) sink_(motion::ebb_command(m));
  }

  const Plan& plan_;
  const DeviceProfile& p_;
  const LineSink& sink_;
  MachineTransform t_;
  motion::EbbGeometry geo_;
  EbbPen pen_;
  motion::MotorSteps at_{0, 0};
  int64_t clock_ticks_ = 0;  // the job's motion clock, 25 a millisecond
  std::vector<motion::MotionBlock> blocks_;
  std::vector<motion::EbbMove> moves_;
};

}  // namespace

void write_ebb(const Plan& plan, const DeviceProfile& profile, const LineSink& out, const EbbOptions& opt) {
  check_ebb_protocol(plan, profile);
  const LineSink sink = !opt.also ? out : LineSink([&](std::string_view l) {
    out(l);
    opt.also(l);
  });
  EbbJobWriter w(plan, profile, sink);
  w.header();
  for (size_t li = 0; li < plan.layers.size(); ++li) {
    if (opt.on_layer) opt.on_layer(li);
    const PlannedLayer& layer = plan.layers[li];
    // One pen holder: every layer after the first is a pen change by hand.
    if (li > 0) w.pause("Change pen: pen " + std::to_string(li + 1) + " " + layer.pen.name + " " + layer.pen.color.hex());
    for (const Stroke& s : layer.strokes)
      if (!s.pts.empty()) w.stroke(s);
  }
  w.travel(MachineTransform(profile, plan.page).to_machine_mm(
      MachineTransform(profile, plan.page).page_position_of_machine_zero()));
}

std::vector<std::string> ebb_commands(const Plan& plan, const DeviceProfile& profile) {
  std::vector<std::string> out;
  write_ebb(plan, profile, [&](std::string_view l) { out.emplace_back(l); });
  return out;
}

void write_ebb_file(const Plan& plan, const DeviceProfile& profile, const std::string& path, const EbbOptions& opt) {
  check_ebb_protocol(plan, profile);  // before the file is created
  write_lines_atomic(path, [&](const LineSink& sink) { write_ebb(plan, profile, sink, opt); }, "\n");
}

}  // namespace stipplot
