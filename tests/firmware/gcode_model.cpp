#include "firmware/gcode_model.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace firmware {

namespace {

std::string clean_line(const std::string& raw) {
  std::string out;
  bool paren = false;
  for (char c : raw) {
    if (paren) {
      paren = c != ')';
      continue;
    }
    if (c == '(') paren = true;
    else if (c == ';') break;
    else if (static_cast<unsigned char>(c) > ' ' && c != '/') out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return out;
}

struct Word {
  char letter;
  double value;
};

std::vector<Word> words_of(const std::string& l, const std::string& raw) {
  std::vector<Word> w;
  size_t i = 0;
  while (i < l.size()) {
    char c = l[i++];
    if (c < 'A' || c > 'Z') throw std::runtime_error("G-code `" + raw + "`: expected a letter at '" + l.substr(i - 1) + "'");
    // grbl's read_float: a sign, digits and one '.', nothing else (no exponent, no hex).
    size_t j = i;
    if (j < l.size() && (l[j] == '-' || l[j] == '+')) ++j;
    bool digits = false, dot = false;
    while (j < l.size() && (std::isdigit(static_cast<unsigned char>(l[j])) || (l[j] == '.' && !dot))) {
      dot = dot || l[j] == '.';
      digits = digits || l[j] != '.';
      ++j;
    }
    if (!digits) throw std::runtime_error("G-code `" + raw + "`: " + std::string(1, c) + " has no number");
    double v = std::strtod(l.substr(i, j - i).c_str(), nullptr);
    i = j;
    w.push_back({c, v});
  }
  return w;
}

// grbl keeps positions as float and rounds to steps in the planner (planner.c:
// target_steps = lround(target * steps_per_mm)).
long to_steps(double mm, double steps_per_mm) {
  return std::lround(static_cast<float>(mm) * static_cast<float>(steps_per_mm));
}

}  // namespace

std::string grbl_line_filter(const std::string& raw) { return clean_line(raw); }

MachineSettings MachineSettings::parse(const std::string& text) {
  MachineSettings s;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    int key;
    double v;
    if (std::sscanf(line.c_str(), "$%d=%lf", &key, &v) != 2) continue;
    if (key >= 100 && key <= 102) s.steps_per_mm[key - 100] = v;
    if (key >= 110 && key <= 112) s.max_rate_mm_min[key - 110] = v;
    if (key >= 120 && key <= 122) s.accel_mm_s2[key - 120] = v;
    if (key == 10) s.status_mask = static_cast<int>(v);
    if (key == 30) s.spindle_max = v;
    if (key == 1) s.idle_lock_ms = v;
    if (key == 20) s.soft_limits = v != 0;
    if (key == 22) s.homing = v != 0;
  }
  return s;
}

MachineSettings MachineSettings::load(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read settings file " + path);
  std::stringstream ss;
  ss << f.rdbuf();
  return parse(ss.str());
}

PenRule PenRule::for_profile(const std::string& name) {
  if (name == "grbl-servo" || name == "grbl-laser") return servo(0);
  if (name == "grbl-z") return z_axis(1.5);  // halfway between the profile's Z 3 (up) and 0 (down)
  throw std::runtime_error("no pen rule for profile " + name);
}

GcodeInterpreter::GcodeInterpreter(const MachineSettings& s, PenRule rule) : set_(s), rule_(rule) {}

void GcodeInterpreter::reset(Steps pos) {
  pos_ = pos;
  const long p[3] = {pos.x, pos.y, pos.z};
  for (int i = 0; i < 3; ++i) target_mm_[i] = p[i] / set_.steps_per_mm[i];
  rapid_ = true;  // gc_init: motion mode G0
  absolute_ = true;
  inches_ = false;
  check_mode_ = false;
  spindle_ = 0;
  s_ = 0;
}

bool GcodeInterpreter::pen_down() const {
  if (rule_.kind == PenRule::Kind::ZAxis) return pos_.z < rule_.z_down_below_mm * set_.steps_per_mm[2];
  return spindle_ != 0 && s_ > rule_.servo_up_s;
}

namespace {

// The words of one line, as grbl's parser groups them (gcode.c, modal groups).
struct ParsedLine {
  int motion = -1, spindle = -1, flow = -1;  // G0/G1; M3/M4/M5; 0 pause, 2 end
  int inches = -1, absolute = -1;            // G20/G21, G90/G91; -1 not given
  bool dwell = false, have_s = false, have_axis[3] = {false, false, false};
  double p = 0, s = 0, axis[3] = {0, 0, 0};
};

ParsedLine parse_words(const std::string& l, const std::string& raw) {
  ParsedLine x;
  for (const Word& w : words_of(l, raw)) {
    const long code10 = std::lround(w.value * 10);
    switch (w.letter) {
      case 'G':
        if (code10 == 0 || code10 == 10) x.motion = static_cast<int>(code10 / 10);
        else if (code10 == 40) x.dwell = true;
        else if (code10 == 200 || code10 == 210) x.inches = code10 == 200;
        else if (code10 == 900 || code10 == 910) x.absolute = code10 == 900;
        else if (code10 == 170 || code10 == 940 || code10 == 540 || code10 == 400 || code10 == 490 || code10 == 800 ||
                 code10 == 610)
          ;  // plane XY, units/min feed, G54, no cutter/tool-length compensation, cancel canned cycle, exact path
        else throw std::runtime_error("G-code `" + raw + "`: G" + std::to_string(code10 / 10.0) + " is not modelled");
        break;
      case 'M':
        if (code10 == 0 || code10 == 10) x.flow = 0;
        else if (code10 == 20 || code10 == 300) x.flow = 2;
        else if (code10 == 30 || code10 == 40 || code10 == 50) x.spindle = static_cast<int>(code10 / 10);
        else if (code10 == 70 || code10 == 80 || code10 == 90) ;  // coolant: no effect on the pen
        else throw std::runtime_error("G-code `" + raw + "`: M" + std::to_string(code10 / 10) + " is not modelled");
        break;
      case 'X': case 'Y': case 'Z':
        x.have_axis[w.letter - 'X'] = true;
        x.axis[w.letter - 'X'] = w.value;
        break;
      case 'S': x.have_s = true; x.s = w.value; break;
      case 'P': x.p = w.value; break;
      case 'F': case 'N': case 'T': break;
      default: throw std::runtime_error("G-code `" + raw + "`: word " + std::string(1, w.letter) + " is not modelled");
    }
  }
  return x;
}

}  // namespace

// Applies grbl's order of execution (gcode.c): spindle speed and state, dwell, units and
// distance mode, the move, then program flow.
LineEffect GcodeInterpreter::feed(const std::string& raw) {
  LineEffect e;
  std::string l = clean_line(raw);
  if (l.empty()) return e;
  if (l[0] == '$') {
    e.system = true;
    if (l == "$C") {
      e.check_mode_toggle = true;
      check_mode_ = !check_mode_;
    }
    return e;
  }
  const ParsedLine x = parse_words(l, raw);
  if (x.inches >= 0) inches_ = x.inches == 1;
  if (x.absolute >= 0) absolute_ = x.absolute == 1;
  if (x.motion >= 0) rapid_ = x.motion == 0;
  const bool any_axis = x.have_axis[0] || x.have_axis[1] || x.have_axis[2];
  if (check_mode_) {  // parsed, state kept, nothing runs
    for (int i = 0; i < 3; ++i)
      if (x.have_axis[i]) target_mm_[i] = (absolute_ ? 0 : target_mm_[i]) + x.axis[i] * (inches_ ? 25.4 : 1);
    if (x.have_s) s_ = x.s;
    if (x.spindle >= 0) spindle_ = x.spindle == 5 ? 0 : x.spindle;
    return e;
  }
  const bool was_down = pen_down();
  if (x.have_s && x.s != s_) {
    if (spindle_ != 0) e.spindle_change = true;
    s_ = x.s;
  }
  if (x.spindle >= 0) {
    int next = x.spindle == 5 ? 0 : x.spindle;
    if (next != spindle_) e.spindle_change = true;
    spindle_ = next;
  }
  if (rule_.kind == PenRule::Kind::Servo && pen_down() != was_down) e.pen_before = pen_down() ? 1 : 0;
  if (x.dwell) e.dwell_s = x.p;
  if (any_axis) {
    e.motion = true;
    e.rapid = rapid_;
    e.from = pos_;
    long st[3] = {pos_.x, pos_.y, pos_.z};
    for (int i = 0; i < 3; ++i) {
      if (!x.have_axis[i]) continue;
      double mm = x.axis[i] * (inches_ ? 25.4 : 1);
      target_mm_[i] = absolute_ ? mm : target_mm_[i] + mm;
      st[i] = to_steps(target_mm_[i], set_.steps_per_mm[i]);
    }
    pos_ = {st[0], st[1], st[2]};
    e.to = pos_;
  }
  if (x.flow == 0) e.pause = true;
  if (x.flow == 2) {  // program end resets G1, G90, M5 (gcode.c)
    e.program_end = true;
    rapid_ = false;
    absolute_ = true;
    if (spindle_ != 0) {
      bool before = pen_down();
      spindle_ = 0;
      e.spindle_change = true;
      if (rule_.kind == PenRule::Kind::Servo && before) e.pen_after = 0;
    }
  }
  e.sync = e.spindle_change || x.dwell || x.flow >= 0;
  return e;
}

bool MarkCollector::z_down(long z_steps) const { return z_steps < rule_.z_down_below_mm * z_steps_per_mm_; }

void MarkCollector::set_down(bool down, Steps at) {
  if (down && !down_) {
    down_ = true;
    moved_ = false;
    at_ = at;
  } else if (!down && down_) {
    if (!moved_) marks_.push_back({Mark::Kind::Dot, at_, at_});
    down_ = false;
  }
}

void MarkCollector::pen(bool down, Steps at) {
  if (rule_.kind == PenRule::Kind::Servo) set_down(down, at);
}

void MarkCollector::move(Steps from, Steps to, bool complete) {
  const bool xy = from.x != to.x || from.y != to.y;
  const bool drawing = rule_.kind == PenRule::Kind::ZAxis ? z_down(from.z) && z_down(to.z) : down_;
  if (drawing && xy) {
    marks_.push_back({complete ? Mark::Kind::Segment : Mark::Kind::Partial, from, to});
    moved_ = true;
  }
  if (rule_.kind == PenRule::Kind::ZAxis) set_down(z_down(to.z), to);
}

void MarkCollector::finish() { set_down(false, at_); }

std::vector<std::string> gcode_lines(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::vector<Mark> expected_marks(const std::string& gcode, const MachineSettings& s, const PenRule& rule) {
  GcodeInterpreter g(s, rule);
  g.reset({});
  MarkCollector c(rule, s.steps_per_mm[2]);
  for (const std::string& line : gcode_lines(gcode)) {
    Steps before = g.position();
    LineEffect e = g.feed(line);
    if (e.pen_before >= 0) c.pen(e.pen_before == 1, before);
    if (e.motion && !(e.from == e.to)) c.move(e.from, e.to, true);
    if (e.pen_after >= 0) c.pen(e.pen_after == 1, g.position());
  }
  c.finish();
  return c.marks();
}

}  // namespace firmware
