#include "drivers/stream/grbl/streamer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "drivers/stream/grbl/codes.hpp"

namespace stipplot::io::grbl {

using clock = std::chrono::steady_clock;

Options options_for(const DeviceProfile& p) {
  Options o;
  o.rx_buffer = p.serial.rx_buffer_bytes;
  o.planner_blocks = p.motion.lookahead_blocks;
  o.watchdog = Millis(static_cast<long>(p.serial.watchdog_s * 1000));
  return o;
}

Expectations expectations_for(const Job& job) {
  Expectations e;
  for (const auto& l : job.lines) {
    e.travel_x = std::max(e.travel_x, l.x);
    e.travel_y = std::max(e.travel_y, l.y);
    e.min_x = std::min(e.min_x, l.x);
    e.min_y = std::min(e.min_y, l.y);
    const std::string& t = l.text;
    for (size_t i = 0; i < t.size(); ++i) {
      if ((t[i] == 'F' || t[i] == 'S') && i + 1 < t.size()) {
        double v = std::strtod(t.c_str() + i + 1, nullptr);
        if (t[i] == 'F') e.speed_mm_s = std::max(e.speed_mm_s, v / 60);
        else e.max_s = std::max(e.max_s, v);
      }
      if (t[i] == 'M' && i + 1 < t.size() && t[i + 1] == '4') e.laser = true;
    }
  }
  return e;
}

Streamer::Streamer(Transport& t, Options o) : t_(t), o_(std::move(o)), reader_(t) {
  if (o_.rx_buffer < 16 || o_.rx_buffer > 1 << 20) throw UserError("rx buffer must be 16..1048576 bytes");
  if (!(o_.poll_hz > 0 && o_.poll_hz <= 50)) throw UserError("status poll rate must be in (0, 50] Hz");
}

void Streamer::note(const std::string& s) {
  if (o_.log) o_.log(s);
}

Status Streamer::query_status(Millis timeout) {
  t_.write("?");
  auto end = clock::now() + timeout;
  std::string line;
  while (clock::now() < end) {
    auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (!reader_.read_line(line, std::max(left, Millis(1)))) break;
    Status s;
    if (parse_status(line, s)) {
      last_status_ = s;
      return s;
    }
  }
  throw TransportError(TransportError::Kind::Timeout, "no status report from grbl on " + t_.describe() + " within " +
                                                          std::to_string(timeout.count()) + " ms");
}

DevicePen Streamer::device_pen(const GcodePenRule& rule) {
  Status s = query_status(Millis(3000));
  DevicePen p;
  p.known = true;
  p.down = gcode_pen_down(s.spindle > 0, s.spindle, s.z, rule);
  p.x = s.x;
  p.y = s.y;
  return p;
}

bool Streamer::wait_for_banner(Millis timeout, Millis slice) {
  auto end = clock::now() + timeout;
  std::string line;
  while (clock::now() < end)
    if (reader_.read_line(line, slice) && classify_reply(line).kind == ReplyKind::Banner) return true;
  return false;
}

void Streamer::soft_reset() {
  t_.write("\x18");
  if (wait_for_banner(o_.banner_timeout)) return;
  throw TransportError(TransportError::Kind::Timeout, "grbl did not restart after a soft reset (Ctrl-X) within " +
                                                          std::to_string(o_.banner_timeout.count()) + " ms");
}

void Streamer::connect() {
  // An Arduino resets when the port opens and prints its banner; a board that did not
  // reset answers a status query instead; failing both, ask for a soft reset.
  bool alive = wait_for_banner(Millis(400), Millis(50));
  restarted_ = alive;
  Status st;
  auto answers = [&] {
    try {
      st = query_status(o_.probe_timeout);
      return true;
    } catch (const TransportError& e) {
      if (e.kind() != TransportError::Kind::Timeout) throw;
      return false;
    }
  };
  // A board that is only slow to answer may be moving: a reset on a move raises ALARM:3
  // and loses the position. So a feed hold first (harmless if it is idle, or not grbl),
  // then one more question; still silent, the hold has long completed when the reset
  // comes (seen on the real firmware once in 60 host kills: no status for 1.9 s).
  if (!alive) alive = answers();
  if (!alive) {
    t_.write("!");
    alive = answers();
  }
  if (!alive) {
    try {
      soft_reset();
      restarted_ = true;
    } catch (const TransportError& e) {
      if (e.kind() != TransportError::Kind::Timeout) throw;
      throw TransportError(TransportError::Kind::Timeout,
                           "no answer from grbl on " + t_.describe() + " within " +
                               std::to_string(o_.banner_timeout.count() / 1000) +
                               " s: is it a grbl device, powered, and set to the profile's baud rate?");
    }
  }
  st = query_status(Millis(3000));
  if (st.state.rfind("Alarm", 0) == 0) {
    if (!o_.unlock)
      throw UserError("grbl is in ALARM state: check the machine, then unlock it (pass --unlock to send $X)");
    system_command("$X", Millis(3000));
    note("grbl was in ALARM; unlocked with $X");
  }
  wait_until_done(st);
  reader_.clear();
}

// grbl reports Idle while it dwells and while it waits for the rest of a line, so Idle
// alone does not mean a dead host's lines have all run: wait for Idle with the planner and
// the receive buffer empty (twice running; without buffer data, Idle for 1.5 s). A hold
// keeps motion nobody is watching: stop it (a reset once the hold is complete keeps the
// position) rather than let it run on. Bytes that stay in the receive buffer with the
// machine idle are a line cut short (the host died writing it): a reset drops them.
void Streamer::wait_until_done(Status st) {
  const auto wait_end = clock::now() + std::chrono::minutes(30);
  auto idle_since = clock::now(), unchanged_since = clock::now();
  int empty_polls = 0;
  Status was = st;
  while (clock::now() < wait_end) {
    const bool idle = st.state == "Idle";
    const bool planner_empty = st.blocks_free < 0 || st.blocks_free >= o_.planner_blocks;
    const bool known = st.bytes_free >= 0;
    empty_polls = idle && planner_empty && known && st.bytes_free >= o_.rx_buffer ? empty_polls + 1 : 0;
    if (!idle) idle_since = clock::now();
    if (st.state != was.state || st.x != was.x || st.y != was.y || st.bytes_free != was.bytes_free) unchanged_since = clock::now();
    if (empty_polls >= 2 || (!known && clock::now() - idle_since > Millis(1500))) return;
    if (st.state == "Hold:0") {
      soft_reset();
      restarted_ = true;
      note("grbl was left in a feed hold with motion buffered: reset it (the resume goes from where it stopped)");
    } else if (idle && planner_empty && known && clock::now() - unchanged_since > Millis(2000)) {
      // Idle with bytes waiting for 2 s: a line cut short (or a dwell on a machine slower
      // than the clock says, about to run the lines behind it). A feed hold first, so that
      // the reset never lands on a move just begun (grbl would raise ALARM:3); a reset in
      // a completed hold keeps the position.
      const bool moved = hold_for_reset();
      soft_reset();
      if (moved) restarted_ = true;  // what it had begun is gone: the resume finds where it stopped
      note("grbl held " + std::to_string(o_.rx_buffer - st.bytes_free) +
           " bytes of a line an earlier session did not finish: reset it to drop them");
    }
    was = st;
    std::this_thread::sleep_for(Millis(100));
    st = query_status(Millis(3000));
  }
}

bool Streamer::hold_for_reset() {
  const Status before = query_status(Millis(3000));
  t_.write("!");
  const auto end = clock::now() + Millis(10000);
  bool moved = false;
  for (;;) {
    const Status st = query_status(Millis(3000));
    moved |= st.state != "Hold:0" || std::abs(st.x - before.x) > 1e-3 || std::abs(st.y - before.y) > 1e-3;
    if (st.state == "Hold:0") return moved;
    if (clock::now() > end)
      throw TransportError(TransportError::Kind::Timeout, "grbl did not come to a feed hold within 10 s (state " + st.state + ")");
    std::this_thread::sleep_for(Millis(50));
  }
}

std::string Streamer::system_command(const std::string& cmd, Millis timeout, std::vector<std::string>* lines) {
  t_.write(cmd + "\n");
  auto end = clock::now() + timeout;
  std::string line;
  while (clock::now() < end) {
    if (!reader_.read_line(line, Millis(50))) continue;
    const Reply r = classify_reply(line);
    if (r.answers_a_line()) return line;
    if (r.kind == ReplyKind::Status) continue;  // a stray status report: not the command's
    if (lines) lines->push_back(line);
    end = clock::now() + timeout;  // the timeout is per line of output
  }
  throw TransportError(TransportError::Kind::Timeout, "no reply from grbl on " + t_.describe());
}

bool Streamer::parser_reset() {
  std::vector<std::string> lines;
  try {
    if (classify_reply(system_command("$G", Millis(2000), &lines)).kind != ReplyKind::Ok) return true;
  } catch (const TransportError& e) {
    if (e.kind() != TransportError::Kind::Timeout) throw;
    return true;
  }
  for (const std::string& line : lines) {
    if (line.rfind("[GC:", 0) != 0) continue;
    const size_t f = line.find(" F");
    double feed = 0;
    return f == std::string::npos || std::sscanf(line.c_str() + f + 2, "%lf", &feed) != 1 || feed == 0;
  }
  return true;
}

std::map<int, double> Streamer::read_settings() {
  std::vector<std::string> lines;
  const std::string answer = system_command("$$", Millis(5000), &lines);
  if (classify_reply(answer).kind == ReplyKind::Error)
    throw UserError("grbl refused $$ (" + answer + "): " + error_meaning(classify_reply(answer).code));
  std::map<int, double> s;
  for (const std::string& line : lines) {
    int k;
    double v;
    if (std::sscanf(line.c_str(), "$%d=%lf", &k, &v) == 2) s[k] = v;
  }
  return s;
}

std::vector<std::string> Streamer::check_settings(const std::map<int, double>& s, const Expectations& e) {
  std::vector<std::string> w;
  auto get = [&](int k) { auto it = s.find(k); return it == s.end() ? -1.0 : it->second; };
  char b[256];
  for (int axis = 0; axis < 2; ++axis) {
    double rate = get(110 + axis);
    if (rate > 0 && e.speed_mm_s * 60 > rate * 1.0001) {
      std::snprintf(b, sizeof b, "grbl's max rate $%d=%.0f mm/min is below the job's feed %.0f mm/min: it will move slower than planned",
                    110 + axis, rate, e.speed_mm_s * 60);
      w.push_back(b);
    }
  }
  if (get(20) > 0) {
    const double lim_x = get(130), lim_y = get(131);
    const bool out = e.travel_x > 1e-6 || e.travel_y > 1e-6 || (lim_x >= 0 && e.min_x < -lim_x - 1e-6) ||
                     (lim_y >= 0 && e.min_y < -lim_y - 1e-6);
    if (out) {
      std::snprintf(b, sizeof b,
                    "the job reaches X %.1f..%.1f, Y %.1f..%.1f mm but with soft limits ($20=1) grbl accepts only "
                    "X -%.1f..0, Y -%.1f..0 ($130, $131): it would stop with ALARM:2",
                    e.min_x, e.travel_x, e.min_y, e.travel_y, lim_x, lim_y);
      throw UserError(b);
    }
  }
  if (get(30) > 0 && e.max_s > get(30) + 1e-9) {
    std::snprintf(b, sizeof b, "the job uses S%.0f but grbl's max spindle speed is $30=%.0f: S values above it are clamped",
                  e.max_s, get(30));
    w.push_back(b);
  }
  if (e.laser && get(32) == 0) w.push_back("laser job but grbl's laser mode is off ($32=0): it will pause at every power change");
  if (!e.laser && get(32) == 1) w.push_back("grbl's laser mode is on ($32=1) but this is not a laser profile");
  if (get(10) >= 0 && !(static_cast<int>(get(10)) & 2))
    w.push_back("grbl's status reports omit buffer data ($10 lacks 2): progress uses acknowledged lines only");
  return w;
}

std::vector<std::pair<long, int>> Streamer::check_job(const Job& job) {
  const Reply entered = classify_reply(system_command("$C", Millis(5000)));
  if (entered.kind == ReplyKind::Error) throw UserError("grbl refused check mode ($C): " + error_meaning(entered.code));
  Options keep = o_;
  o_.skip_errors = true;
  o_.log = {};
  StreamResult res;
  try {
    res = stream(job, 0, {}, nullptr);
  } catch (...) {
    o_ = keep;
    throw;
  }
  o_ = keep;
  // Leaving check mode soft-resets grbl.
  t_.write("$C\n");
  wait_for_banner(o_.banner_timeout);
  reader_.clear();
  return res.errors;
}

}  // namespace stipplot::io::grbl
