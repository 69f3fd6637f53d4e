#include "sim/grbl_sim.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

#include "drivers/device/motion_setup.hpp"
#include "drivers/device/pen_rule.hpp"

namespace stipplot::sim {

namespace {

// "#N line": a line tagged with its number, for the reply faults (built by appending:
// GCC 12 warns falsely about chained string concatenation, its bug 105651).
std::string tagged_line(long no, const std::string& clean) {
  std::string out = "#";
  out += std::to_string(no);
  out += ' ';
  out += clean;
  return out;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string fmt3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

struct Word {
  char letter;
  double value;
};

// A letter and a number each; 0 or grbl's error code (1: no letter, 2: bad number).
int parse_words(const std::string& line, std::vector<Word>& words) {
  for (size_t i = 0; i < line.size();) {
    char l = line[i];
    if (!std::isalpha(static_cast<unsigned char>(l))) return 1;
    ++i;
    size_t s = i;
    while (i < line.size() && (std::isdigit(static_cast<unsigned char>(line[i])) || line[i] == '.' || line[i] == '-' ||
                               line[i] == '+'))
      ++i;
    if (s == i) return 2;
    char* end = nullptr;
    std::string num = line.substr(s, i - s);
    double v = std::strtod(num.c_str(), &end);
    if (!end || *end != '\0' || !std::isfinite(v)) return 2;
    words.push_back({l, v});
  }
  return 0;
}

// grbl's line filter: spaces and comments dropped as it reads, letters upper-cased.
std::string filter_line(const std::string& raw) {
  std::string clean;
  bool paren = false;
  for (char ch : raw) {
    if (paren) {
      paren = ch != ')';
      continue;
    }
    if (ch == '(') paren = true;
    else if (ch == ';') break;
    else if (ch != ' ' && ch != '\t') clean.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(ch))));
  }
  return clean;
}

}  // namespace

GrblSimConfig grbl_sim_config(const DeviceProfile& p) {
  GrblSimConfig c;
  c.machine = grbl_settings_for(p);
  c.pen = gcode_pen_rule(p);
  c.travel = {p.machine.travel_x_mm, p.machine.travel_y_mm, 50};
  c.rx_buffer = p.serial.rx_buffer_bytes;
  c.laser_mode = p.pen.method == PenMethod::laser;
  return c;
}

GrblSim::GrblSim(const GrblSimConfig& cfg) : SimDevice(cfg), cfg_(cfg), motion_(cfg.machine) {
  if (cfg.rx_buffer < 16) throw UserError("simulated grbl: rx buffer must be at least 16 bytes");
  const motion::GrblSettings& m = cfg.machine;
  settings_ = {{0, 10},     {1, m.idle_lock_s > 0 ? m.idle_lock_s * 1000 : 255}, {2, 0}, {3, 0}, {4, 0}, {5, 0},
               {6, 0},      {10, cfg.status_mask}, {11, m.junction_deviation_mm}, {12, 0.002}, {13, 0},
               {20, cfg.soft_limits ? 1.0 : 0.0}, {21, 0}, {22, cfg.homing || cfg.soft_limits ? 1.0 : 0.0},
               {23, 0},     {24, 25},   {25, 500},  {26, 250},  {27, 1},   {30, 1000}, {31, 0},
               {32, cfg.laser_mode ? 1.0 : 0.0}};
  for (int i = 0; i < 3; ++i) {
    settings_[100 + i] = m.steps_per_mm[static_cast<size_t>(i)];
    settings_[110 + i] = m.max_rate_mm_min[static_cast<size_t>(i)];
    settings_[120 + i] = m.accel_mm_s2[static_cast<size_t>(i)];
    settings_[130 + i] = cfg.travel[static_cast<size_t>(i)];
  }
  if (settings_[22] != 0) alarm_ = true;  // HOMING_INIT_LOCK: home or unlock first
}

GrblSim::~GrblSim() { stop(); }

size_t GrblSim::boots() const {
  std::lock_guard lk(m_);
  return boots_;
}

bool GrblSim::pen_down_state() const {
  return io::gcode_pen_down(spindle_ != 0 && !spindle_stopped_in_hold_, spindle_s_, motion_.position()[2], cfg_.pen);
}

void GrblSim::set_pen(bool down) {
  std::lock_guard lk(m_);
  rec_.pen(down);
}

bool GrblSim::idle() const {
  return !machine_busy() && !line_ && !pause_m0_ && booting_until_ < 0 && rx_.find_first_of("\r\n") == std::string::npos;
}

void GrblSim::on_connect(double t) {
  now_ = std::max(now_, t);
  if (replies_ == 0 && lines_seen_ == 0 && boots_ == 0) send(std::string(banner) + "\r\n", t);  // power-on banner
}

void GrblSim::on_client_open(double t) {
  if (cfg_.reset_on_open) boot(t);
  else if (booting_until_ == kInf) booting_until_ = t + cfg_.boot_s;  // powered on again
}

// Motion stops where it is and everything is lost, as at a reset; the board stays off
// (nothing answered, bytes ignored) until a client opens the port again.
void GrblSim::on_power_loss(double t) {
  boot(t);
  booting_until_ = kInf;
}

void GrblSim::on_disconnect(double) {
  // Lines not yet accepted are lost with the link; accepted ones still run.
  rx_.clear();
  line_.reset();
}

// An Arduino rebooted by DTR: motion stops where it is, everything buffered is lost,
// the position is zeroed (the record assumes the operator re-zeroed the machine), and the
// bootloader ignores bytes for a moment before grbl prints its banner.
void GrblSim::boot(double t) {
  interrupted_ = -2;  // power lost: nothing is answered
  halt(t);
  {
    std::lock_guard lk(m_);
    rec_.pen(false);
    rec_.move(0, 0);
    ++boots_;
  }
  motion_.set_position({0, 0, 0});
  parser_pos_ = {0, 0, 0};
  hold_ = pause_m0_ = check_ = need_reset_ = spindle_stopped_in_hold_ = false;
  motion_mode_ = 0, absolute_ = true, inches_ = false, feed_ = 0;
  alarm_ = settings_[22] != 0;
  booting_until_ = t + cfg_.boot_s;
  mark_paused();
}

void GrblSim::on_byte(char c, double t) {
  if (booting_until_ >= 0) return;  // the bootloader swallows what comes meanwhile
  const unsigned char u = static_cast<unsigned char>(c);
  switch (u) {
    case '?': status(t); return;
    case '!':
      // As grbl 1.1h: a hold in any state but alarm and check mode; from idle it is
      // complete at once (Hold:0).
      if (!hold_ && !alarm_ && !check_) {
        hold_ = true;
        motion_.hold(t);
        mark_paused();
      }
      return;
    case '~':
      if (hold_ || pause_m0_) {
        hold_ = false;
        spindle_stopped_in_hold_ = false;
        motion_.resume(t);
        set_pen(pen_down_state());
        if (pause_m0_) {
          pause_m0_ = false;
          line_.reset();
          send("ok\r\n", t);
          ++replies_;
        }
        mark_paused();
        if (!machine_busy()) mark_idle(t);
        process(t);
      }
      return;
    case 0x18: reset(t); return;
    case 0x9E:  // spindle stop override: lifts a servo pen during a hold
      if (hold_) {
        {
          std::lock_guard lk(m_);
          const motion::Vec3 at = traced_position();
          rec_.move(at[0], at[1]);  // the pen leaves the paper where the hold stopped it
        }
        spindle_stopped_in_hold_ = !spindle_stopped_in_hold_;
        set_pen(pen_down_state());
      }
      return;
    default: break;
  }
  if (u >= 0x80) return;  // other real-time overrides: ignored
  if (static_cast<int>(rx_.size()) >= cfg_.rx_buffer) {
    std::lock_guard lk(m_);
    ++stats_.rx_overflow;  // a streamer that overfills the buffer loses bytes
    return;
  }
  rx_.push_back(c);
  if (c == '\n' || c == '\r') process(t);
}

void GrblSim::process(double t) {
  while (true) {
    // A dwell, the idle lock or a stall hold grbl's main loop: nothing more is parsed.
    if (stall_until_ > t || need_reset_ || dwell_until_ > 0 || booting_until_ >= 0 || motion_.in_idle_lock(t)) return;
    if (!line_) {
      auto eol = rx_.find_first_of("\r\n");
      if (eol == std::string::npos) return;
      std::string clean = filter_line(rx_.substr(0, eol));
      rx_.erase(0, eol + 1);
      if (!clean.empty() && clean[0] != '$') {
        const long no = ++lines_seen_;
        {
          std::lock_guard lk(m_);
          ++stats_.lines;
        }
        if (clean.size() > 79) {
          send("error:11\r\n", t);
          continue;
        }
        if (no == faults_.reset_line) {  // the reset (abort) input: a soft reset mid-job
          reset(t);
          return;
        }
        if (no == faults_.stall_line && faults_.stall_ms > 0) {
          stall_until_ = t + faults_.stall_ms / 1000.0;
          line_ = tagged_line(no, clean);
          return;
        }
        if (no == faults_.error_line) {
          std::lock_guard lk(m_);
          ++stats_.errors;
          send("error:" + std::to_string(faults_.error_code) + "\r\n", t);
          continue;
        }
        if (no == faults_.alarm_line) {
          alarm(1, t);
          return;
        }
        clean = tagged_line(no, clean);
      }
      line_ = clean;
    }
    if (execute_line(*line_, t) == Result::Blocked) return;
    line_.reset();
  }
}

void GrblSim::reply(long no, const std::string& r, double t) {
  if (no >= 0 && no == faults_.drop_reply) return;
  if (no >= 0 && no == faults_.corrupt_reply) {
    send("o\x8bk\r\n", t);
    return;
  }
  if (r.rfind("error", 0) == 0) {
    std::lock_guard lk(m_);
    ++stats_.errors;
  }
  send(r + "\r\n", t);
  ++replies_;
}

// The words of a line applied to a copy of the modal state: 0 or grbl's error code
// (20 unsupported, 4 negative value, 22 no feed rate, 28 G4 without P). Nothing is
// committed yet.
int GrblSim::interpret(const std::string& line, LineEffect& e) const {
  std::vector<Word> words;
  if (int err = parse_words(line, words)) return err;
  e.motion = motion_mode_;
  e.absolute = absolute_;
  e.inches = inches_;
  e.feed = feed_;
  e.s_val = spindle_s_;
  e.spindle = spindle_;
  for (const Word& w : words) {
    switch (w.letter) {
      case 'G': {
        int g = static_cast<int>(std::lround(w.value * 10));
        if (g == 0 || g == 10) e.motion = g / 10;
        else if (g == 40) e.dwell = true;
        else if (g == 200) e.inches = true;
        else if (g == 210) e.inches = false;
        else if (g == 900) e.absolute = true;
        else if (g == 910) e.absolute = false;
        else if (g != 170 && g != 940 && g != 540) return 20;  // G17 G94 G54: accepted, no effect here
        break;
      }
      case 'M': {
        int mm = static_cast<int>(std::lround(w.value));
        if (mm == 0 || mm == 1) e.m0 = true;
        else if (mm == 2 || mm == 30) e.m2 = true;
        else if (mm == 3 || mm == 4) e.spindle = mm;
        else if (mm == 5) e.spindle = 0;
        else if (mm != 7 && mm != 8 && mm != 9) return 20;  // coolant: accepted, no effect
        break;
      }
      case 'F':
      case 'S':
        if (w.value < 0) return 4;
        if (w.letter == 'F') e.feed = w.value;
        else e.s_val = w.value;
        break;
      case 'P': e.p = w.value, e.have_p = true; break;
      case 'X': e.ax[0] = true, e.val[0] = w.value; break;
      case 'Y': e.ax[1] = true, e.val[1] = w.value; break;
      case 'Z': e.ax[2] = true, e.val[2] = w.value; break;
      case 'N':
      case 'T': break;
      default: return 20;
    }
  }
  const double scale = e.inches ? 25.4 : 1;
  for (size_t k = 0; k < 3; ++k)
    e.target[k] = !e.ax[k] ? parser_pos_[k] : e.absolute ? e.val[k] * scale : parser_pos_[k] + e.val[k] * scale;
  if (e.dwell && !e.have_p) return 28;
  if (e.axes() && !e.dwell && e.motion == 1 && e.feed <= 0) return 22;
  return 0;
}

// grbl 1.1h without HOMING_FORCE_SET_ORIGIN: soft limits allow machine positions in
// [-max travel, 0] on every axis (limits.c, system_check_travel_limits).
bool GrblSim::outside_soft_limits(const motion::Vec3& target) const {
  if (settings_.at(20) == 0) return false;
  for (int k = 0; k < 3; ++k)
    if (target[static_cast<size_t>(k)] > 1e-9 || target[static_cast<size_t>(k)] < -settings_.at(130 + k) - 1e-9) return true;
  return false;
}

// As grbl's protocol loop: every line gets one answer (ok or error:N), except a line
// that waits (for the planner to empty or make room, or for the cycle start after M0),
// which is answered when it has run.
GrblSim::Result GrblSim::execute_line(const std::string& tagged, double t) {
  long no = -1;
  std::string line = tagged;
  if (!line.empty() && line[0] == '#') {
    auto sp = line.find(' ');
    no = std::strtol(line.c_str() + 1, nullptr, 10);
    line = line.substr(sp + 1);
  }
  if (line.empty()) {
    reply(no, "ok", t);
    return Result::Done;
  }
  if (line[0] == '$') return execute_system(line, t);
  if (alarm_) {
    reply(no, "error:9", t);
    return Result::Done;
  }
  LineEffect e;
  if (int err = interpret(line, e)) {
    reply(no, "error:" + std::to_string(err), t);
    return Result::Done;
  }
  // grbl (gcode.c) syncs a change of spindle state, a new S while it runs (not in laser
  // mode), a dwell and the program flow words.
  const bool spindle_change = e.spindle != spindle_ || (e.spindle != 0 && e.s_val != spindle_s_ && settings_[32] == 0);
  const bool sync = e.dwell || e.m0 || e.m2 || spindle_change;
  if (!check_ && sync && machine_busy()) return Result::Blocked;
  const bool moves = e.axes() && !e.dwell;
  if (moves) {
    if (outside_soft_limits(e.target)) {
      alarm(2, t);
      return Result::Done;
    }
    if (!check_ && !motion_.has_room()) return Result::Blocked;
  }
  return accept(e, no, t);
}

// The line is accepted: its modes are committed and it runs (or queues its move).
GrblSim::Result GrblSim::accept(const LineEffect& e, long no, double t) {
  motion_mode_ = e.motion;
  absolute_ = e.absolute;
  inches_ = e.inches;
  feed_ = e.feed;
  const bool moves = e.axes() && !e.dwell;
  if (check_) {
    spindle_ = e.m2 ? 0 : e.spindle;
    spindle_s_ = e.s_val;
    if (moves) parser_pos_ = e.target;
    reply(no, "ok", t);
    return Result::Done;
  }
  const bool spindle_changed = (e.m2 ? 0 : e.spindle) != spindle_ || e.s_val != spindle_s_;
  spindle_ = e.m2 ? 0 : e.spindle;
  spindle_s_ = e.s_val;
  if (spindle_changed) set_pen(pen_down_state());
  if (e.dwell) {
    dwell_until_ = t + motion::grbl_dwell_seconds(e.p);
    if (dwell_until_ <= t) {
      dwell_until_ = 0;
      reply(no, "ok", t);
      return Result::Done;
    }
    mark_busy(t);
    dwell_no_ = no;  // ok comes when the dwell ends
    return Result::Done;
  }
  if (e.m0) {
    pause_m0_ = true;
    mark_paused();
    return Result::Blocked;  // ok when resumed with '~'
  }
  if (moves) {
    const double scale = e.inches ? 25.4 : 1;
    if (motion_.plan(e.target, e.feed * scale, e.motion == 0, no, t)) {
      std::lock_guard lk(m_);
      ++stats_.blocks;
    }
    parser_pos_ = e.target;
    mark_busy(t);
  }
  reply(no, "ok", t);
  return Result::Done;
}

// The machine up to t: every block that ends is recorded, and grbl's main loop goes on
// (a line waiting for room or for the machine to stop may now run).
void GrblSim::run_motion(double t) {
  while (true) {
    const double next = motion_.next_event();
    if (!(next <= t)) break;
    motion_.advance(next);
    now_ = next;
    bool finished = false;
    for (const auto& f : motion_.take_finished()) {
      std::lock_guard lk(m_);
      rec_.move(f.target[0], f.target[1]);  // what the job asked for, within a step
      finished = true;
    }
    if (finished) set_pen(pen_down_state());
    if (!motion_.busy()) mark_idle(next);
    process(next);
  }
  motion_.advance(t);
}

void GrblSim::advance(double t) {
  while (true) {
    double next = kInf;
    if (dwell_until_ > 0 && !hold_) next = std::min(next, dwell_until_);
    if (stall_until_ > 0) next = std::min(next, stall_until_);
    if (booting_until_ >= 0) next = std::min(next, booting_until_);
    if (next > t) break;
    run_motion(next);
    now_ = next;
    if (booting_until_ >= 0 && booting_until_ <= next) {
      booting_until_ = -1;
      send(std::string(banner) + "\r\n", next);
      if (alarm_) send("[MSG:'$H'|'$X' to unlock]\r\n", next);
    }
    if (dwell_until_ > 0 && dwell_until_ <= next && !hold_) {
      dwell_until_ = 0;
      if (!(dwell_no_ >= 0 && dwell_no_ == faults_.drop_reply)) {
        send(dwell_no_ >= 0 && dwell_no_ == faults_.corrupt_reply ? "o\x8bk\r\n" : "ok\r\n", next);
        ++replies_;
      }
      mark_idle(next);
    }
    if (stall_until_ > 0 && stall_until_ <= next) stall_until_ = 0;
    process(next);
  }
  run_motion(t);
  now_ = std::max(now_, t);
}

double GrblSim::next_event() const {
  double next = motion_.next_event();
  if (dwell_until_ > 0 && !hold_) next = std::min(next, dwell_until_);
  if (stall_until_ > 0) next = std::min(next, stall_until_);
  if (booting_until_ >= 0) next = std::min(next, booting_until_);
  return next;
}

void GrblSim::status(double t) {
  std::string state = alarm_  ? "Alarm"
                      : check_ ? "Check"
                      : hold_  ? (motion_.hold_complete() ? "Hold:0" : "Hold:1")
                      : pause_m0_ ? "Hold:0"
                      : motion_.moving() ? "Run"
                                         : "Idle";
  const motion::Vec3 p = motion_.position();
  std::string r = "<" + state + "|MPos:" + fmt3(p[0]) + "," + fmt3(p[1]) + "," + fmt3(p[2]);
  if (static_cast<int>(settings_.at(10)) & 2) {
    const int blocks = motion_.settings().planner_blocks - static_cast<int>(motion_.planned());
    const int bytes = cfg_.rx_buffer - static_cast<int>(rx_.size());
    r += "|Bf:" + std::to_string(blocks) + "," + std::to_string(bytes);
  }
  char fs[64];
  std::snprintf(fs, sizeof fs, "|FS:%.0f,%.0f>", motion_.speed() * 60, spindle_ ? spindle_s_ : 0.0);
  send(r + fs + "\r\n", t);
}

// The machine stops where it is (grbl keeps the step count as its position); the
// planner, the receive buffer and a dwell are dropped, and the spindle (the pen) goes off.
void GrblSim::halt(double t) {
  run_motion(t);
  {
    std::lock_guard lk(m_);
    const motion::Vec3 at = traced_position();
    rec_.move(at[0], at[1]);
  }
  motion_.halt();
  parser_pos_ = motion_.position();
  rx_.clear();
  line_.reset();
  dwell_until_ = 0;
  stall_until_ = 0;
  spindle_ = 0;
  set_pen(pen_down_state());
}

// Where the tool is, on the line the job asked for: the step position (Bresenham's,
// up to a step off the straight line) projected onto the running block's programmed
// line, as finished blocks are recorded at their programmed ends.
motion::Vec3 GrblSim::traced_position() const {
  motion::Vec3 p = motion_.position();
  if (motion_.blocks().empty()) {  // at rest where the last move ended, as it was recorded
    p[0] = rec_.x();
    p[1] = rec_.y();
    return p;
  }
  const motion::Vec3& to = motion_.blocks().front().target;
  const double x0 = rec_.x(), y0 = rec_.y(), dx = to[0] - x0, dy = to[1] - y0, len2 = dx * dx + dy * dy;
  if (len2 <= 0) return p;
  const double u = std::clamp(((p[0] - x0) * dx + (p[1] - y0) * dy) / len2, 0.0, 1.0);
  p[0] = x0 + u * dx;
  p[1] = y0 + u * dy;
  return p;
}

// The line grbl's parser was executing, waiting for the planner to empty or have room or
// dwelling (-2: none): on an abort those waits return and the line is still answered ok
// (protocol.c protocol_buffer_synchronize, planner waits in motion_control.c mc_line and
// mc_dwell's delay_sec all return on sys.abort; gc_execute_line then reports STATUS_OK).
long GrblSim::line_under_way() const {
  if (line_) return !line_->empty() && (*line_)[0] == '#' ? std::strtol(line_->c_str() + 1, nullptr, 10) : -2;
  if (dwell_until_ > 0) return dwell_no_;
  return -2;
}

void GrblSim::reset(double t) {
  if (interrupted_ == -2) interrupted_ = line_under_way();
  if (interrupted_ != -2) reply(interrupted_, "ok", t);  // before the reset's banner
  interrupted_ = -2;
  const bool moving = motion_.moving() && !motion_.hold_complete();
  halt(t);
  hold_ = pause_m0_ = check_ = need_reset_ = false;
  spindle_stopped_in_hold_ = false;
  motion_mode_ = 0;
  absolute_ = true;
  inches_ = false;
  feed_ = 0;
  mark_paused();
  if (moving) {
    alarm_ = true;
    send("ALARM:3\r\n", t);
    std::lock_guard lk(m_);
    ++stats_.alarms;
  }
  send(std::string(banner) + "\r\n", t);
  if (alarm_) send("[MSG:'$H'|'$X' to unlock]\r\n", t);
}

void GrblSim::alarm(int code, double t) {
  // A critical alarm waits for the host's reset before the interrupted line is answered.
  interrupted_ = line_under_way();
  send("ALARM:" + std::to_string(code) + "\r\n", t);
  {
    std::lock_guard lk(m_);
    ++stats_.alarms;
  }
  halt(t);
  hold_ = pause_m0_ = false;
  alarm_ = true;
  need_reset_ = true;
  mark_paused();
  send("[MSG:Reset to continue]\r\n", t);
}

std::string GrblSim::settings_text() const {
  std::string s;
  char b[64];
  for (const auto& [k, v] : settings_) {
    if (v == std::floor(v) && std::abs(v) < 1e9) std::snprintf(b, sizeof b, "$%d=%.0f\r\n", k, v);
    else std::snprintf(b, sizeof b, "$%d=%.3f\r\n", k, v);
    s += b;
  }
  return s;
}

void GrblSim::apply_settings() {
  motion::GrblSettings m = motion_.settings();
  for (size_t i = 0; i < 3; ++i) {
    m.steps_per_mm[i] = settings_[100 + static_cast<int>(i)];
    m.max_rate_mm_min[i] = settings_[110 + static_cast<int>(i)];
    m.accel_mm_s2[i] = settings_[120 + static_cast<int>(i)];
  }
  m.junction_deviation_mm = settings_[11];
  m.idle_lock_s = motion::GrblSettings::idle_lock_from_setting(settings_[1]);
  const motion::Vec3 p = motion_.position();
  motion_ = motion::GrblMotion(m);
  motion_.set_position(p);
}

GrblSim::Result GrblSim::execute_system(const std::string& line, double t) {
  auto ok = [&] {
    send("ok\r\n", t);
    ++replies_;
  };
  const bool cycle = motion_.moving() || hold_ || pause_m0_ || dwell_until_ > 0;
  if (line == "$") {
    send("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]\r\n", t);
    ok();
  } else if (line == "$$") {
    if (cycle) send("error:8\r\n", t);  // grbl: blocked during a cycle or a hold
    else {
      send(settings_text(), t);
      ok();
    }
  } else if (line == "$G") {
    send(std::string("[GC:G") + (motion_mode_ ? "1" : "0") + " G54 G17 " + (inches_ ? "G20" : "G21") +
             (absolute_ ? " G90" : " G91") + " G94 " + (spindle_ == 3 ? "M3" : spindle_ == 4 ? "M4" : "M5") +
             " M9 T0 F" + fmt3(feed_) + " S" + fmt3(spindle_s_) + "]\r\n",
         t);
    ok();
  } else if (line == "$X") {
    if (alarm_) send("[MSG:Caution: Unlocked]\r\n", t);
    alarm_ = false;
    ok();
  } else if (line == "$C") {
    if (check_) {
      send("[MSG:Disabled]\r\n", t);
      ok();
      reset(t);
    } else if (cycle || alarm_) {
      send("error:8\r\n", t);
    } else {
      check_ = true;
      send("[MSG:Enabled]\r\n", t);
      ok();
    }
  } else if (cycle || !(line.size() > 1)) {
    send(cycle ? "error:8\r\n" : "error:3\r\n", t);  // everything else needs IDLE or ALARM
  } else if (line == "$I") {
    send("[VER:1.1h.20190825:stipplot-sim]\r\n[OPT:V," + std::to_string(motion_.settings().planner_blocks) + "," +
             std::to_string(cfg_.rx_buffer) + "]\r\n",
         t);
    ok();
  } else if (line == "$H") {
    if (settings_[22] == 0) send("error:5\r\n", t);
    else {
      {
        std::lock_guard lk(m_);
        rec_.pen(false);
        rec_.move(0, 0);
      }
      motion_.set_position({0, 0, 0});
      parser_pos_ = {0, 0, 0};
      alarm_ = false;
      ok();
    }
  } else if (line == "$#") {
    send("[G54:0.000,0.000,0.000]\r\n[G55:0.000,0.000,0.000]\r\n[G92:0.000,0.000,0.000]\r\n[TLO:0.000]\r\n[PRB:0.000,0.000,0.000:0]\r\n", t);
    ok();
  } else if (std::isdigit(static_cast<unsigned char>(line[1])) && line.find('=') != std::string::npos) {
    int k = std::atoi(line.c_str() + 1);
    double v = std::strtod(line.c_str() + line.find('=') + 1, nullptr);
    if (!settings_.count(k)) send("error:3\r\n", t);
    else if (v < 0) send("error:4\r\n", t);
    else if (k == 20 && v != 0 && settings_[22] == 0) send("error:10\r\n", t);
    else {
      settings_[k] = v;
      apply_settings();
      ok();
    }
  } else {
    send("error:3\r\n", t);
  }
  return Result::Done;
}

}  // namespace stipplot::sim
