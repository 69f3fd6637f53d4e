#include "sim/grbl_sim.hpp"

#include "drivers/device/pen_rule.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

namespace stipplot::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A block moving from v0 to v1 with cruise vn (both <= vn) over L at acceleration a.
struct Trapezoid {
  double t_acc, t_cruise, t_dec, v_peak;
  double total() const { return t_acc + t_cruise + t_dec; }
};
Trapezoid trapezoid(double L, double v0, double v1, double vn, double a) {
  double d_acc = (vn * vn - v0 * v0) / (2 * a), d_dec = (vn * vn - v1 * v1) / (2 * a);
  if (d_acc + d_dec <= L) return {(vn - v0) / a, (L - d_acc - d_dec) / vn, (vn - v1) / a, vn};
  double vp = std::sqrt(std::max(0.0, (2 * a * L + v0 * v0 + v1 * v1) / 2));
  vp = std::max({vp, v0, v1});
  return {(vp - v0) / a, 0, (vp - v1) / a, vp};
}
double distance_at(const Trapezoid& tr, double v0, double a, double L, double t) {
  if (t <= 0) return 0;
  if (t < tr.t_acc) return v0 * t + 0.5 * a * t * t;
  double s = v0 * tr.t_acc + 0.5 * a * tr.t_acc * tr.t_acc;
  t -= tr.t_acc;
  if (t < tr.t_cruise) return s + tr.v_peak * t;
  s += tr.v_peak * tr.t_cruise;
  t -= tr.t_cruise;
  t = std::min(t, tr.t_dec);
  return std::min(L, s + tr.v_peak * t - 0.5 * a * t * t);
}

std::string fmt3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

}  // namespace

GrblSimConfig grbl_sim_config(const DeviceProfile& p) {
  GrblSimConfig c;
  c.motion = p.motion;
  c.pen = gcode_pen_rule(p);
  c.travel_x = p.machine.travel_x_mm;
  c.travel_y = p.machine.travel_y_mm;
  c.rx_buffer = p.serial.rx_buffer_bytes;
  return c;
}

GrblSim::GrblSim(const GrblSimConfig& cfg) : SimDevice(cfg), cfg_(cfg) {
  const MotionParams& m = cfg.motion;
  if (!(m.accel_mm_s2 > 0) || !(m.speed_up_mm_s > 0) || !(m.speed_down_mm_s > 0))
    throw UserError("simulated grbl: speeds and acceleration must be > 0");
  if (cfg.rx_buffer < 16) throw UserError("simulated grbl: rx buffer must be at least 16 bytes");
  double rate = std::max(m.speed_up_mm_s, m.speed_down_mm_s) * 60;
  settings_ = {{0, 10},    {1, 25},     {2, 0},      {3, 0},      {4, 0},     {5, 0},      {6, 0},
               {10, 3},    {11, m.junction_deviation_mm}, {12, 0.002}, {13, 0},  {20, cfg.soft_limits ? 1.0 : 0.0},
               {21, 0},    {22, cfg.soft_limits ? 1.0 : 0.0}, {23, 0}, {24, 25}, {25, 500}, {26, 250}, {27, 1},
               {30, 1000}, {31, 0},     {32, 0},     {100, 80},   {101, 80},  {102, 400},
               {110, rate}, {111, rate}, {112, cfg.z_speed_mm_s * 60},
               {120, m.accel_mm_s2}, {121, m.accel_mm_s2}, {122, cfg.z_accel_mm_s2},
               {130, cfg.travel_x}, {131, cfg.travel_y}, {132, cfg.travel_z}};
}

GrblSim::~GrblSim() { stop(); }

bool GrblSim::pen_down_state() const {
  return io::gcode_pen_down(spindle_on_ && !spindle_stopped_in_hold_, spindle_s_, mz_, cfg_.pen);
}

void GrblSim::set_pen(bool down) {
  std::lock_guard lk(m_);
  rec_.pen(down);
}

bool GrblSim::idle() const { return !machine_busy() && !line_ && rx_.find_first_of("\r\n") == std::string::npos; }

void GrblSim::on_connect(double t) {
  now_ = std::max(now_, t);
  if (replies_ == 0 && lines_seen_ == 0) send(std::string(banner) + "\r\n", t);  // power-on banner
}

void GrblSim::on_disconnect(double) {
  // Lines not yet accepted are lost with the link; accepted ones still run.
  rx_.clear();
  line_.reset();
  if (pause_m0_) pause_m0_ = false;
}

void GrblSim::on_byte(char c, double t) {
  unsigned char u = static_cast<unsigned char>(c);
  switch (u) {
    case '?': status(t); return;
    case '!':
      if (!hold_ && (machine_busy() || pause_m0_)) {
        hold_ = true;
        mark_paused();
      }
      return;
    case '~':
      if (hold_ || pause_m0_) {
        hold_ = false;
        spindle_stopped_in_hold_ = false;
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
    // A dwell holds grbl's protocol loop: nothing more is parsed until it ends.
    if (stall_until_ > t || need_reset_ || dwell_until_ > 0) return;
    if (!line_) {
      auto eol = rx_.find_first_of("\r\n");
      if (eol == std::string::npos) return;
      std::string raw = rx_.substr(0, eol);
      rx_.erase(0, eol + 1);
      // grbl drops spaces and comments as it reads, and upper-cases.
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
      if (!clean.empty() && clean[0] != '$') {
        long no = ++lines_seen_;
        {
          std::lock_guard lk(m_);
          ++stats_.lines;
        }
        if (clean.size() > 79) {
          send("error:11\r\n", t);
          continue;
        }
        if (no == faults_.stall_line && faults_.stall_ms > 0) {
          stall_until_ = t + faults_.stall_ms / 1000.0;
          line_ = clean;
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
        std::string tagged = "#";  // remember the number for reply faults
        tagged += std::to_string(no);
        tagged += ' ';
        tagged += clean;
        clean.swap(tagged);
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

namespace {
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
}  // namespace

// The words of a line applied to a copy of the modal state: 0 or grbl's error code
// (20 unsupported, 4 negative value). Nothing is committed yet.
int GrblSim::interpret(const std::string& line, LineEffect& e) const {
  std::vector<Word> words;
  if (int err = parse_words(line, words)) return err;
  e.motion = motion_mode_;
  e.absolute = absolute_;
  e.inches = inches_;
  e.feed = feed_;
  e.s_val = spindle_s_;
  e.spindle_on = spindle_on_;
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
        if (mm == 0) e.m0 = true;
        else if (mm == 2 || mm == 30) e.m2 = true;
        else if (mm == 3 || mm == 4) e.spindle_on = true, e.spindle_cmd = true;
        else if (mm == 5) e.spindle_on = false, e.spindle_cmd = true;
        else if (mm != 7 && mm != 8 && mm != 9) return 20;  // coolant: accepted, no effect
        break;
      }
      case 'F':
      case 'S':
        if (w.value < 0) return 4;
        if (w.letter == 'F') e.feed = w.value;
        else e.s_val = w.value, e.spindle_cmd = true;
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
  double cur[3] = {px_, py_, pz_};
  for (int k = 0; k < 3; ++k) e.target[k] = !e.ax[k] ? cur[k] : e.absolute ? e.val[k] * scale : cur[k] + e.val[k] * scale;
  if (e.dwell && !e.have_p) return 28;
  if (e.axes() && e.motion == 1 && (e.inches ? e.feed * 25.4 : e.feed) <= 0) return 22;
  return 0;
}

bool GrblSim::outside_soft_limits(const double target[3]) {
  return settings_[20] != 0 && (target[0] < -1e-9 || target[0] > settings_[130] + 1e-9 || target[1] < -1e-9 ||
                                target[1] > settings_[131] + 1e-9 || std::abs(target[2]) > settings_[132] + 1e-9);
}

// As grbl's protocol loop: every line gets one answer (ok or error:N), except a line
// that waits (for the planner to empty or make room, or for the cycle start after M0),
// which is answered when it has run.
GrblSim::Result GrblSim::execute_line(const std::string& tagged, double t) {
  long no = -1;
  std::string line = tagged;
  if (!line.empty() && line[0] == '#') {  // the line number, for reply faults
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
  // Commands that wait for the planner to empty (grbl synchronises these).
  bool sync = e.dwell || e.m0 || e.m2 || (e.spindle_cmd && (e.spindle_on != spindle_on_ || (e.spindle_on && e.s_val != spindle_s_)));
  if (sync && machine_busy()) return Result::Blocked;
  const bool moves = e.axes() && !e.dwell;
  if (moves) {
    if (outside_soft_limits(e.target)) {
      alarm(2, t);
      return Result::Done;
    }
    if (!check_ && static_cast<int>(planner_.size()) + (current_ ? 1 : 0) >= cfg_.motion.lookahead_blocks)
      return Result::Blocked;
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
    spindle_on_ = e.spindle_on;
    spindle_s_ = e.s_val;
    if (moves) px_ = e.target[0], py_ = e.target[1], pz_ = e.target[2];
    reply(no, "ok", t);
    return Result::Done;
  }
  if (e.spindle_cmd || e.m2) {
    spindle_on_ = e.m2 ? false : e.spindle_on;
    spindle_s_ = e.s_val;
    set_pen(pen_down_state());
  }
  if (e.dwell) {
    dwell_until_ = t + std::max(0.0, e.p);
    dwell_ok_pending_ = true;
    mark_busy(t);
    dwell_no_ = no;  // ok comes when the dwell ends
    return Result::Done;
  }
  if (e.m0) {
    pause_m0_ = true;
    mark_paused();
    return Result::Blocked;  // ok when resumed with '~'
  }
  if (e.axes()) {
    queue_move(e.target, e.motion == 0 ? -1 : e.feed * (e.inches ? 25.4 : 1) / 60, t);
    px_ = e.target[0], py_ = e.target[1], pz_ = e.target[2];
  }
  reply(no, "ok", t);
  return Result::Done;
}

// A block from the parser's position to `target` at `feed_mm_s` (< 0: rapid, at the
// axes' max rates), with grbl's junction-deviation speed at the corner into it.
void GrblSim::queue_move(const double target[3], double feed_mm_s, double t) {
  Block b{};
  b.x0 = px_, b.y0 = py_, b.z0 = pz_;
  b.x1 = target[0], b.y1 = target[1], b.z1 = target[2];
  double dx = b.x1 - b.x0, dy = b.y1 - b.y0, dz = b.z1 - b.z0;
  b.len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (!(b.len > 1e-9)) return;  // grbl drops zero-length blocks
  b.ux = dx / b.len, b.uy = dy / b.len, b.uz = dz / b.len;
  double rate[3] = {settings_[110] / 60, settings_[111] / 60, settings_[112] / 60};
  double acc[3] = {settings_[120], settings_[121], settings_[122]};
  double u[3] = {b.ux, b.uy, b.uz};
  double vmax = kInf, amax = kInf;
  for (int k = 0; k < 3; ++k)
    if (std::abs(u[k]) > 1e-12) {
      vmax = std::min(vmax, rate[k] / std::abs(u[k]));
      amax = std::min(amax, acc[k] / std::abs(u[k]));
    }
  b.v_nom = feed_mm_s < 0 ? vmax : std::min(vmax, feed_mm_s);
  b.accel = amax;
  // Junction deviation (grbl): the corner speed a circle of deviation jd allows.
  if (have_last_dir_ && planner_.size() + (current_ ? 1 : 0) > 0) {
    double cos_theta = -(b.ux * last_ux_ + b.uy * last_uy_ + b.uz * last_uz_);
    if (cos_theta > 0.999999) b.v_junction = 0;
    else if (cos_theta < -0.999999) b.v_junction = kInf;
    else {
      double sin_half = std::sqrt(0.5 * (1 - cos_theta));
      b.v_junction = std::sqrt(b.accel * settings_[11] * sin_half / (1 - sin_half));
    }
    b.v_junction = std::min({b.v_junction, b.v_nom, last_v_nom_});
  } else {
    b.v_junction = 0;
  }
  last_ux_ = b.ux, last_uy_ = b.uy, last_uz_ = b.uz, last_v_nom_ = b.v_nom;
  have_last_dir_ = true;
  planner_.push_back(b);
  {
    std::lock_guard lk(m_);
    ++stats_.blocks;
  }
  if (!current_) start_block(t);
}

void GrblSim::start_block(double t) {
  if (planner_.empty()) return;
  current_ = planner_.front();
  planner_.pop_front();
  Block& b = *current_;
  // Backward pass over what is queued: the last queued block must be able to stop.
  double next_entry = 0;
  for (auto it = planner_.rbegin(); it != planner_.rend(); ++it) {
    double e = std::min({it->v_junction, it->v_nom, std::sqrt(next_entry * next_entry + 2 * it->accel * it->len)});
    next_entry = e;
  }
  if (planner_.empty()) next_entry = 0;
  b.v_entry = std::min(prev_exit_v_, b.v_nom);
  b.v_exit = std::min({next_entry, b.v_nom, std::sqrt(b.v_entry * b.v_entry + 2 * b.accel * b.len)});
  // The entry must allow stopping at the exit speed within the block.
  b.v_entry = std::min(b.v_entry, std::sqrt(b.v_exit * b.v_exit + 2 * b.accel * b.len));
  b.duration = trapezoid(b.len, b.v_entry, b.v_exit, b.v_nom, b.accel).total();
  b.elapsed = 0;
  mark_busy(t);
}

void GrblSim::finish_block(double t) {
  const Block& b = *current_;
  mx_ = b.x1, my_ = b.y1, mz_ = b.z1;
  {
    std::lock_guard lk(m_);
    rec_.move(b.x1, b.y1);
  }
  set_pen(pen_down_state());
  prev_exit_v_ = b.v_exit;
  current_.reset();
  if (!planner_.empty()) start_block(t);
  else {
    prev_exit_v_ = 0;
    mark_idle(t);
  }
}

double GrblSim::position_in_block(const Block& b, double elapsed, double& x, double& y, double& z) const {
  Trapezoid tr = trapezoid(b.len, b.v_entry, b.v_exit, b.v_nom, b.accel);
  double s = distance_at(tr, b.v_entry, b.accel, b.len, elapsed);
  x = b.x0 + b.ux * s, y = b.y0 + b.uy * s, z = b.z0 + b.uz * s;
  if (elapsed < tr.t_acc) return b.v_entry + b.accel * elapsed;
  if (elapsed < tr.t_acc + tr.t_cruise) return tr.v_peak;
  return std::max(0.0, tr.v_peak - b.accel * (elapsed - tr.t_acc - tr.t_cruise));
}

void GrblSim::advance(double t) {
  while (true) {
    if (hold_) {
      now_ = std::max(now_, t);
      return;
    }
    if (current_) {
      double remaining = current_->duration - current_->elapsed;
      if (now_ + remaining <= t) {
        double te = now_ + remaining;
        now_ = te;
        finish_block(te);
        process(te);
        continue;
      }
      current_->elapsed += t - now_;
      now_ = t;
      return;
    }
    if (dwell_until_ > 0) {
      if (dwell_until_ <= t) {
        double te = dwell_until_;
        now_ = te;
        dwell_until_ = 0;
        if (dwell_ok_pending_) {
          dwell_ok_pending_ = false;
          if (!(dwell_no_ >= 0 && dwell_no_ == faults_.drop_reply)) {
            send(dwell_no_ >= 0 && dwell_no_ == faults_.corrupt_reply ? "o\x8bk\r\n" : "ok\r\n", te);
            ++replies_;
          }
        }
        mark_idle(te);
        process(te);
        continue;
      }
      now_ = t;
      return;
    }
    if (stall_until_ > 0 && stall_until_ <= t) {
      double te = stall_until_;
      stall_until_ = 0;
      now_ = te;
      process(te);
      continue;
    }
    now_ = std::max(now_, t);
    return;
  }
}

double GrblSim::next_event() const {
  if (hold_) return kInf;
  if (current_) return now_ + (current_->duration - current_->elapsed);
  if (dwell_until_ > 0) return dwell_until_;
  if (stall_until_ > 0) return stall_until_;
  return kInf;
}

void GrblSim::status(double t) {
  std::string state = alarm_ ? "Alarm" : check_ ? "Check" : (hold_ || pause_m0_) ? "Hold:0" : (current_ || !planner_.empty()) ? "Run" : "Idle";
  double x = mx_, y = my_, z = mz_, v = 0;
  if (current_) v = position_in_block(*current_, current_->elapsed, x, y, z);
  if (hold_) v = 0;
  int blocks = cfg_.motion.lookahead_blocks - static_cast<int>(planner_.size()) - (current_ ? 1 : 0);
  int bytes = cfg_.rx_buffer - static_cast<int>(rx_.size());
  char fs[64];
  std::snprintf(fs, sizeof fs, "|FS:%.0f,%.0f>", v * 60, spindle_on_ ? spindle_s_ : 0.0);
  send("<" + state + "|MPos:" + fmt3(x) + "," + fmt3(y) + "," + fmt3(z) + "|Bf:" + std::to_string(blocks) + "," +
           std::to_string(bytes) + fs + "\r\n",
       t);
}

// The machine stops where it is (the machine position is now mid-block); the planner,
// the receive buffer and a dwell are dropped, and the spindle (the pen) goes off.
void GrblSim::halt() {
  if (current_) {
    double x, y, z;
    position_in_block(*current_, current_->elapsed, x, y, z);
    mx_ = x, my_ = y, mz_ = z;
  }
  current_.reset();
  planner_.clear();
  rx_.clear();
  line_.reset();
  dwell_until_ = 0;
  spindle_on_ = false;
  set_pen(pen_down_state());
}

void GrblSim::reset(double t) {
  bool moving = current_.has_value() && !hold_;
  halt();
  hold_ = pause_m0_ = check_ = need_reset_ = false;
  spindle_stopped_in_hold_ = false;
  dwell_ok_pending_ = false;
  stall_until_ = 0;
  prev_exit_v_ = 0;
  have_last_dir_ = false;
  {
    std::lock_guard lk(m_);
    rec_.move(mx_, my_);
  }
  px_ = mx_, py_ = my_, pz_ = mz_;
  motion_mode_ = 0;
  absolute_ = true;
  inches_ = false;
  feed_ = 0;
  mark_paused();
  if (moving) {
    alarm_ = true;
    send("ALARM:3\r\n", t);
  }
  send(std::string(banner) + "\r\n", t);
  if (alarm_) send("[MSG:'$H'|'$X' to unlock]\r\n", t);
}

void GrblSim::alarm(int code, double t) {
  send("ALARM:" + std::to_string(code) + "\r\n", t);
  {
    std::lock_guard lk(m_);
    ++stats_.alarms;
  }
  halt();
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

GrblSim::Result GrblSim::execute_system(const std::string& line, double t) {
  auto ok = [&] {
    send("ok\r\n", t);
    ++replies_;
  };
  bool busy = machine_busy() || hold_ || pause_m0_;
  if (line == "$") {
    send("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]\r\n", t);
    ok();
  } else if (busy && line != "$$" && line != "$G") {
    send("error:8\r\n", t);
  } else if (line == "$$") {
    send(settings_text(), t);
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
    } else {
      check_ = true;
      send("[MSG:Enabled]\r\n", t);
      ok();
    }
  } else if (line == "$G") {
    send(std::string("[GC:G") + (motion_mode_ ? "1" : "0") + " G54 G17 " + (inches_ ? "G20" : "G21") +
             (absolute_ ? " G90" : " G91") + " G94 " + (spindle_on_ ? "M3" : "M5") + " M9 T0 F" + fmt3(feed_) +
             " S" + fmt3(spindle_s_) + "]\r\n",
         t);
    ok();
  } else if (line == "$I") {
    send("[VER:1.1h.20190825:stipplot-sim]\r\n[OPT:V," + std::to_string(cfg_.motion.lookahead_blocks) + "," +
             std::to_string(cfg_.rx_buffer) + "]\r\n",
         t);
    ok();
  } else if (line == "$H") {
    if (settings_[22] == 0) send("error:5\r\n", t);
    else {
      mx_ = my_ = mz_ = 0;
      px_ = py_ = pz_ = 0;
      {
        std::lock_guard lk(m_);
        rec_.move(0, 0);
      }
      alarm_ = false;
      ok();
    }
  } else if (line == "$#") {
    send("[G54:0.000,0.000,0.000]\r\n[G92:0.000,0.000,0.000]\r\n[TLO:0.000]\r\n[PRB:0.000,0.000,0.000:0]\r\n", t);
    ok();
  } else if (line.size() > 1 && std::isdigit(static_cast<unsigned char>(line[1])) && line.find('=') != std::string::npos) {
    int k = std::atoi(line.c_str() + 1);
    double v = std::strtod(line.c_str() + line.find('=') + 1, nullptr);
    if (!settings_.count(k)) send("error:3\r\n", t);
    else if (v < 0) send("error:4\r\n", t);
    else if (k == 20 && v != 0 && settings_[22] == 0) send("error:10\r\n", t);
    else {
      settings_[k] = v;
      ok();
    }
  } else {
    send("error:3\r\n", t);
  }
  return Result::Done;
}

}  // namespace stipplot::sim
