#include "sim/hpgl_sim.hpp"

#include "drivers/job/hpgl_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

namespace stipplot::sim {

namespace {
constexpr double kNever = std::numeric_limits<double>::infinity();
bool is_sep(char c) { return c == ';' || c == '\n' || c == '\r' || c == ' ' || c == '\t' || c == ','; }
}  // namespace

HpglSimConfig hpgl_sim_config(const DeviceProfile& p) {
  HpglSimConfig c;
  c.motion = p.motion;
  c.units_per_mm = p.machine.units_per_mm;
  if (p.serial.rx_buffer_bytes >= 64) c.buffer_bytes = p.serial.rx_buffer_bytes;
  // XOFF must arrive before the host overfills the buffer: leave room for the bytes in
  // flight (latency and the host's reaction, scaled by the speedup).
  c.xoff_free = c.buffer_bytes * 3 / 8;
  c.xon_free = c.buffer_bytes * 5 / 8;
  c.xonxoff = p.hpgl.handshake == HpglHandshake::xonxoff;
  return c;
}

HpglSim::HpglSim(const HpglSimConfig& cfg)
    : SimDevice(cfg), cfg_(cfg), vs_mm_s_(cfg.motion.speed_down_mm_s) {
  plotter_ = motion::hpgl_motion_of(cfg.motion, cfg.units_per_mm);
  if (cfg.buffer_bytes < 64) throw UserError("simulated HPGL plotter: buffer must be at least 64 bytes");
  if (!(cfg.units_per_mm > 0)) throw UserError("simulated HPGL plotter: units per mm must be > 0");
  if (cfg.xoff_free >= cfg.xon_free || cfg.xon_free > cfg.buffer_bytes)
    throw UserError("simulated HPGL plotter: need xoff_free < xon_free <= buffer size");
}

HpglSim::~HpglSim() { stop(); }

void HpglSim::on_connect(double t) { now_ = std::max(now_, t); }

void HpglSim::on_disconnect(double) {
  // Whatever is in the buffer still gets plotted (the plotter does not know the line
  // went down); only bytes in flight are lost.
}

// The instruction under way stops undrawn (its moves are recorded as it ends), the
// buffer and the state are gone; powered on again at the origin, pen up, as after IN.
void HpglSim::on_power_loss(double t) {
  buf_.clear();
  exec_bytes_ = 0;
  executing_ = false;
  pending_moves_.clear();
  pen_down_ = pending_pen_ = false;
  absolute_ = true;
  error_ = 0;
  not_ready_ = xoff_sent_ = false;
  ready_at_ = -1;
  x_ = y_ = 0;
  vs_mm_s_ = cfg_.motion.speed_down_mm_s;
  {
    std::lock_guard lk(m_);
    rec_.pen(false);
    rec_.move(0, 0);
  }
  mark_idle(t);
}

bool HpglSim::idle() const { return !executing_ && buf_.find_first_not_of("; \r\n\t,") == std::string::npos; }

void HpglSim::query_reply(const std::string& r, double t) {
  long k = ++replies_;
  if (k == faults_.drop_reply) return;
  if (k == faults_.corrupt_reply) {
    send("9?x\r", t);
    return;
  }
  send(r + "\r", t);
}

void HpglSim::device_control(char cmd, double t) {
  switch (cmd) {
    case 'B': query_reply(std::to_string(free_bytes()), t); break;
    case 'L': query_reply(std::to_string(cfg_.buffer_bytes), t); break;
    case 'E': query_reply(error_ == 7 ? "15" : "0", t); break;
    case 'O': {
      // 8: buffer empty and idle; 16: not ready (paper lever / alarm); 32: an error is pending (OE).
      int s = (idle() ? 8 : 0) | (not_ready_ ? 16 : 0) | (error_ ? 32 : 0);
      query_reply(std::to_string(s), t);
      break;
    }
    case 'A': query_reply("7475A-sim,1", t); break;
    case 'K':  // abort graphics: drop what is buffered (not the running instruction)
      buf_.erase(std::min(buf_.size(), exec_bytes_));
      check_flow(t);
      break;
    case 'R': not_ready_ = false; break;
    default: break;
  }
}

void HpglSim::check_flow(double t) {
  if (!cfg_.xonxoff) return;
  if (!xoff_sent_ && free_bytes() < cfg_.xoff_free) {
    send("\x13", t);
    xoff_sent_ = true;
  } else if (xoff_sent_ && free_bytes() >= cfg_.xon_free) {
    send("\x11", t);
    xoff_sent_ = false;
  }
}

void HpglSim::on_byte(char c, double t) {
  // Device-control sequences (ESC . x) bypass the buffer and are answered at once.
  if (esc_state_ == 0 && c == 0x1b) {
    esc_state_ = 1;
    return;
  }
  if (esc_state_ == 1) {
    esc_state_ = c == '.' ? 2 : 0;
    return;
  }
  if (esc_state_ == 2) {
    esc_cmd_ = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (std::string("@HIMNT").find(esc_cmd_) != std::string::npos) {
      esc_state_ = 3;
      return;
    }
    esc_state_ = 0;
    device_control(esc_cmd_, t);
    return;
  }
  if (esc_state_ == 3) {
    if (c == ':' || c == ';') esc_state_ = 0;
    return;
  }
  if (free_bytes() <= 0) {
    std::lock_guard lk(m_);
    ++stats_.rx_overflow;
    error_ = 7;
    return;
  }
  buf_.push_back(c);
  check_flow(t);
  if (!executing_) start_next(t);
}

// The next complete instruction at the front of the buffer: two letters, then
// parameters up to ';' or the next letter (a label: up to ETX). Its length, or 0 while
// it is not all there yet.
size_t HpglSim::complete_instruction() const {
  const bool label = std::toupper(static_cast<unsigned char>(buf_[0])) == 'L' &&
                     std::toupper(static_cast<unsigned char>(buf_[1])) == 'B';
  if (label) {
    auto etx = buf_.find('\x03', 2);
    return etx == std::string::npos ? 0 : etx + 1;
  }
  size_t e = 2;
  while (e < buf_.size() && buf_[e] != ';' && !std::isalpha(static_cast<unsigned char>(buf_[e]))) ++e;
  if (e == buf_.size()) return 0;
  return buf_[e] == ';' ? e + 1 : e;
}

void HpglSim::start_next(double t) {
  if (executing_ || not_ready_) return;
  // Separators between instructions are consumed at once.
  size_t s = 0;
  while (s < buf_.size() && is_sep(buf_[s])) ++s;
  if (s) {
    buf_.erase(0, s);
    check_flow(t);
  }
  if (buf_.size() < 2) {
    if (buf_.empty()) mark_idle(t);
    return;
  }
  const size_t e = complete_instruction();
  if (e == 0) {
    if (free_bytes() <= 0) {  // an instruction longer than the buffer: cannot ever finish
      error_ = 7;
      buf_.clear();
      check_flow(t);
    }
    return;
  }
  std::string mn = {static_cast<char>(std::toupper(static_cast<unsigned char>(buf_[0]))),
                    static_cast<char>(std::toupper(static_cast<unsigned char>(buf_[1])))};
  std::string params = buf_.substr(2, e - 2);
  if (!params.empty() && params.back() == ';') params.pop_back();
  const std::vector<double> nums = io::hpgl_numbers(params);
  long no = ++instr_seen_;
  {
    std::lock_guard lk(m_);
    ++stats_.lines;
  }
  const bool pen_before = pen_down_;
  pending_moves_.clear();
  double dur = 0;
  if (no == faults_.error_line) {
    error_ = 1;
    std::lock_guard lk(m_);
    ++stats_.errors;
  } else if (no == faults_.alarm_line) {
    not_ready_ = true;
    if (faults_.not_ready_ms > 0) ready_at_ = t + faults_.not_ready_ms / 1000;
    std::lock_guard lk(m_);
    ++stats_.alarms;
    return;  // stops here, the instruction stays in the buffer
  } else {
    dur = execute(mn, nums, t);
  }
  const MotionParams& m = cfg_.motion;
  if (pen_down_ != pen_before) dur += pen_down_ ? m.pen_drop_s : m.pen_lift_s;
  if (no == faults_.stall_line) dur += faults_.stall_ms / 1000.0;
  exec_bytes_ = e;
  executing_ = true;
  busy_until_ = t + dur;
  pending_pen_ = pen_down_;
  mark_busy(t);
}

// What an instruction does at once (modes, replies, the pen number) and the moves it
// leaves pending until it ends; returns how long it takes, pen moves aside.
double HpglSim::execute(const std::string& mn, const std::vector<double>& nums, double t) {
  const MotionParams& m = cfg_.motion;
  double dur = 0;
  if (mn == "IN") {
    pen_down_ = false;
    absolute_ = true;
    error_ = 0;
    vs_mm_s_ = m.speed_down_mm_s;
  } else if (mn == "SP") {
    if (nums.size() > 1) error_ = 2;
    pen_down_ = false;
    dur += plotter_.pen_change_s;  // the carousel turns
    std::lock_guard lk(m_);
    rec_.pen(false);
    rec_.set_pen_number(nums.empty() ? 0 : static_cast<int>(nums[0]));
  } else if (mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR") {
    if (nums.size() % 2) error_ = 2;
    if (mn == "PU") pen_down_ = false;
    if (mn == "PD") pen_down_ = true;
    if (mn == "PA") absolute_ = true;
    if (mn == "PR") absolute_ = false;
    double cx = x_, cy = y_;
    for (size_t k = 0; k + 1 < nums.size(); k += 2) {
      double nx = absolute_ ? nums[k] : cx + nums[k], ny = absolute_ ? nums[k + 1] : cy + nums[k + 1];
      dur += motion::hpgl_move_seconds(plotter_, nx - cx, ny - cy, pen_down_ ? vs_mm_s_ : m.speed_up_mm_s);
      pending_moves_.push_back({nx, ny});
      cx = nx, cy = ny;
    }
  } else if (mn == "VS") {
    if (!nums.empty() && nums[0] > 0) vs_mm_s_ = nums[0] * 10;
  } else if (mn == "OE") {
    query_reply(std::to_string(error_), t);
    error_ = 0;
  } else if (mn == "OS") {
    query_reply(std::to_string(8 | (error_ ? 32 : 0)), t);
  } else if (mn == "OI") {
    query_reply("7475A", t);
  } else if (mn == "OA") {
    query_reply(std::to_string(static_cast<long>(x_)) + "," + std::to_string(static_cast<long>(y_)) + "," +
                    (pen_down_ ? "1" : "0"),
                t);
  } else if (std::string("DF IP SC IW CS LT LB PT RO DI SI SL CA SS").find(mn) == std::string::npos) {
    error_ = 1;
  }
  return dur;
}

void HpglSim::advance(double t) {
  if (not_ready_ && ready_at_ >= 0 && ready_at_ <= t) {  // the lever is down again: go on
    not_ready_ = false;
    ready_at_ = -1;
    start_next(t);
  }
  while (executing_ && busy_until_ <= t) {
    double te = busy_until_;
    now_ = te;
    {
      std::lock_guard lk(m_);
      // PU/PD x,y: the pen goes to its state first, then moves.
      rec_.pen(pending_pen_);
      for (auto [x, y] : pending_moves_) rec_.move(x, y);
    }
    if (!pending_moves_.empty()) {
      x_ = pending_moves_.back().first;
      y_ = pending_moves_.back().second;
    }
    pending_moves_.clear();
    buf_.erase(0, std::min(exec_bytes_, buf_.size()));
    exec_bytes_ = 0;
    executing_ = false;
    check_flow(te);
    start_next(te);
    if (!executing_) mark_idle(te);
  }
  now_ = std::max(now_, t);
}

double HpglSim::next_event() const {
  const double ready = not_ready_ && ready_at_ >= 0 ? ready_at_ : kNever;
  return std::min(ready, executing_ ? busy_until_ : kNever);
}

}  // namespace stipplot::sim
