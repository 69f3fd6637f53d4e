#include "drivers/writers/gcode_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "drivers/device/machine.hpp"
#include "util/decimal_text.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

// Digits after the point needed to print multiples of `step` exactly (0.01 -> 2, 0.025 -> 3).
int decimals_for(double step) {
  for (int d = 0; d <= 6; ++d) {
    double scaled = step * std::pow(10.0, d);
    if (std::fabs(scaled - std::round(scaled)) < 1e-6) return d;
  }
  return 6;
}

class GcodeEmitter {
 public:
  GcodeEmitter(const Plan& plan, const DeviceProfile& p, const LineSink& sink, const GcodeOptions& opt)
      : plan_(plan), p_(p), sink_(sink), opt_(opt), t_(p, plan.page), decimals_(decimals_for(t_.step_mm())) {
    pow10_ = 1;
    for (int i = 0; i < decimals_; ++i) pow10_ *= 10;
    double k = t_.step_mm() * static_cast<double>(pow10_);
    if (decimals_ < 6 && std::fabs(k - std::round(k)) < 1e-6) step_units_ = std::llround(k);
  }

  void run() {
    size_t strokes = 0;
    for (const auto& l : plan_.layers) strokes += l.strokes.size();
    if (opt_.comments) {
      comment("stipplot G-code for profile " + p_.name + ": " + p_.description);
      std::string page = "page ";
      append_decimal(page, plan_.page.width_mm, 3);
      page += " x ";
      append_decimal(page, plan_.page.height_mm, 3);
      page += " mm, " + std::to_string(plan_.layers.size()) + " layer(s), " + std::to_string(strokes) + " stroke(s)";
      comment(page);
    }
    emit("G21");  // millimetres
    emit("G90");  // absolute
    emit("G94");  // feed per minute
    pen_up(true);
    for (size_t li = 0; li < plan_.layers.size(); ++li) {
      const PlannedLayer& layer = plan_.layers[li];
      if (opt_.on_layer) opt_.on_layer(li);
      std::string label = "layer " + std::to_string(li + 1) + " pen " + layer.pen.name + " (" +
                          layer.pen.color.hex() + ")";
      if (li > 0) {
        pen_up(false);
        // grbl prints "(MSG,...)" as [MSG:...] and waits at M0 until cycle start (~).
        // G-code comments do not nest and grbl's line buffer holds 80 characters, so
        // the message carries no parentheses and is kept short.
        const int pen = layer.pen.number > 0 ? layer.pen.number : static_cast<int>(li) + 1;
        std::string msg = "Change pen: pen " + std::to_string(pen) + " " + layer.pen.name + " " + layer.pen.color.hex();
        for (char& ch : msg)
          if (ch == '(' || ch == ')') ch = ' ';
        if (msg.size() > 60) msg.resize(60);
        emit("M0 (MSG," + msg + ")");
      } else if (opt_.comments) {
        comment(label);
      }
      for (const auto& s : layer.strokes) stroke(s);
    }
    pen_up(false);
    move_rapid({0, 0});
    if (p_.pen.method == PenMethod::laser || p_.pen.method == PenMethod::servo) emit("M5");
    emit("M2");
  }

 private:
  void emit(const std::string& line) {
    if (recording_) {
      recording_->push_back(line);
      return;
    }
    sink_(line);
    if (opt_.also) opt_.also(line);
  }
  void comment(const std::string& text) { emit("; " + text); }

  void xy(std::string& line, Steps s) {
    line += " X";
    coordinate(line, s.x);
    line += " Y";
    coordinate(line, s.y);
  }

  // steps * step_mm printed exactly: with step = k / 10^decimals (k whole) the value is the
  // integer steps*k with the point `decimals` digits from the right, zeros trimmed.
  void coordinate(std::string& out, int64_t steps) {
    if (step_units_ <= 0) {
      append_decimal(out, static_cast<double>(steps) * t_.step_mm(), decimals_);
      return;
    }
    int64_t v = steps * step_units_;
    if (v < 0) {
      out += '-';
      v = -v;
    }
    int64_t whole = v / pow10_, frac = v % pow10_;
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, whole);
    out.append(buf, static_cast<size_t>(r.ptr - buf));
    if (frac) {
      char digits[16];
      int d = decimals_;
      for (int i = d - 1; i >= 0; --i) {
        digits[i] = static_cast<char>('0' + frac % 10);
        frac /= 10;
      }
      while (d > 0 && digits[d - 1] == '0') --d;
      out += '.';
      out.append(digits, static_cast<size_t>(d));
    }
  }

  void feed(std::string& line, double mm_s) {
    const double f = mm_s * 60.0;
    if (f == feed_) return;
    feed_ = f;
    line += " F";
    append_decimal(line, f, 1);
  }

  void move_rapid(Steps s) {
    if (have_pos_ && s == pos_) return;
    std::string line = "G0";
    xy(line, s);
    emit(line);
    pos_ = s;
    have_pos_ = true;
  }

  // M3 S<s> (servo position) or M4 S<s> (laser power).
  void spindle(const char* m, double s) {
    std::string line = m;
    line += " S";
    append_decimal(line, s, 3);
    emit(line);
  }

  void dwell(double seconds) {
    if (seconds <= 0) return;
    std::string line = "G4 P";
    append_decimal(line, seconds, 3);
    emit(line);
  }

  // The pen's moves are the same lines every time: made once, then emitted as they are
  // (a 1M-dot job has 2M of them, and printing their numbers was a tenth of its writing).
  void pen_down() {
    if (down_) return;
    pen_move(true);
    down_ = true;
  }

  void pen_up(bool force) {
    if (!down_ && !force) return;
    pen_move(false);
    down_ = false;
  }

  // A Z axis's moves set the modal feed, which the XY moves depend on: made each time.
  void pen_move(bool down) {
    if (p_.pen.method == PenMethod::z_axis) return down ? make_pen_down() : make_pen_up();
    std::vector<std::string>& lines = down ? down_lines_ : up_lines_;
    if (lines.empty()) lines = recorded([&] { down ? make_pen_down() : make_pen_up(); });
    for (const auto& l : lines) emit(l);
  }

  // The lines f emits, recorded instead.
  template <class F>
  std::vector<std::string> recorded(F&& f) {
    std::vector<std::string> lines;
    recording_ = &lines;
    f();
    recording_ = nullptr;
    return lines;
  }

  void make_pen_down() {
    std::string line;
    switch (p_.pen.method) {
      case PenMethod::servo:
        spindle("M3", p_.pen.servo_down_s);
        dwell(p_.motion.pen_drop_s);
        break;
      case PenMethod::z_axis:
        line = "G1 Z";
        append_decimal(line, p_.pen.z_down_mm, 3);
        feed(line, p_.pen.z_feed_mm_s);
        emit(line);
        break;
      case PenMethod::laser:
        spindle("M4", p_.pen.laser_power_s);
        dwell(p_.motion.pen_drop_s);
        break;
      case PenMethod::hpgl:
      case PenMethod::ebb:
        throw std::logic_error("G-code writer given an HPGL or EBB profile");
    }
  }

  void make_pen_up() {
    std::string line;
    switch (p_.pen.method) {
      case PenMethod::servo:
        if (p_.pen.servo_up_s > 0) spindle("M3", p_.pen.servo_up_s);
        else emit("M5");
        dwell(p_.motion.pen_lift_s);
        break;
      case PenMethod::z_axis:
        line = "G0 Z";
        append_decimal(line, p_.pen.z_up_mm, 3);
        emit(line);
        break;
      case PenMethod::laser:
        emit("M5");
        dwell(p_.motion.pen_lift_s);
        break;
      case PenMethod::hpgl:
      case PenMethod::ebb:
        throw std::logic_error("G-code writer given an HPGL or EBB profile");
    }
  }

  void stroke(const Stroke& s) {
    if (s.pts.empty()) return;
    Steps first = t_.to_steps(s.pts[0]);
    if (!(down_ && have_pos_ && first == pos_)) {
      pen_up(false);
      move_rapid(first);
    }
    pen_down();
    bool drew = false;
    for (size_t i = 1; i < s.pts.size(); ++i) {
      Steps q = t_.to_steps(s.pts[i]);
      if (q == pos_) continue;  // shorter than the resolution
      std::string line = "G1";
      xy(line, q);
      feed(line, p_.motion.speed_down_mm_s);
      emit(line);
      pos_ = q;
      drew = true;
    }
    if (!drew) dwell(p_.pen.dot_dwell_s);
    pen_up(false);
  }

  const Plan& plan_;
  const DeviceProfile& p_;
  const LineSink& sink_;
  const GcodeOptions& opt_;
  MachineTransform t_;
  int decimals_;
  int64_t pow10_ = 1;
  int64_t step_units_ = 0;  // step_mm * 10^decimals when whole, else 0 (printf path)
  Steps pos_;
  bool have_pos_ = false;
  bool down_ = false;
  double feed_ = -1;
  std::vector<std::string> down_lines_, up_lines_;  // the pen's moves, once made
  std::vector<std::string>* recording_ = nullptr;
};

}  // namespace

void write_gcode(const Plan& plan, const DeviceProfile& profile, const LineSink& sink, const GcodeOptions& opt) {
  if (profile.protocol != Protocol::grbl)
    throw UserError("profile " + profile.name + " speaks " + to_string(profile.protocol) + ", not G-code; write .hpgl");
  check_plan_fits(plan, profile);
  GcodeEmitter(plan, profile, sink, opt).run();
}

namespace {
// write_gcode for a plan already checked against the device.
void write_checked_gcode(const Plan& plan, const DeviceProfile& profile, const LineSink& sink, const GcodeOptions& opt) {
  GcodeEmitter(plan, profile, sink, opt).run();
}
}  // namespace

std::vector<std::string> gcode_lines(const Plan& plan, const DeviceProfile& profile, const GcodeOptions& opt) {
  std::vector<std::string> out;
  write_gcode(plan, profile, [&](std::string_view l) { out.emplace_back(l); }, opt);
  return out;
}

void write_gcode_file(const Plan& plan, const DeviceProfile& profile, const std::string& path,
                      const GcodeOptions& opt) {
  if (profile.protocol != Protocol::grbl)
    throw UserError("profile " + profile.name + " speaks " + to_string(profile.protocol) + ", not G-code; write .hpgl");
  check_plan_fits(plan, profile);  // before the file is created
  write_lines_atomic(path, [&](const LineSink& sink) { write_checked_gcode(plan, profile, sink, opt); });
}

}  // namespace stipplot
