#include "firmware/firmware_record.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace firmware {

namespace {

double length_mm(Steps a, Steps b, const MachineSettings& s) {
  double dx = (b.x - a.x) / s.steps_per_mm[0], dy = (b.y - a.y) / s.steps_per_mm[1], dz = (b.z - a.z) / s.steps_per_mm[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// grbl's block acceleration: each axis limited to its own $12x (planner.c
// limit_value_by_axis_maximum).
double block_accel(Steps a, Steps b, const MachineSettings& s) {
  const double d[3] = {(b.x - a.x) / s.steps_per_mm[0], (b.y - a.y) / s.steps_per_mm[1], (b.z - a.z) / s.steps_per_mm[2]};
  double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double acc = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i)
    if (d[i] != 0) acc = std::min(acc, s.accel_mm_s2[i] * len / std::abs(d[i]));
  return std::isfinite(acc) ? acc : s.accel_mm_s2[0];
}

// The time a block's first step takes from rest (and its last one to rest): one step of
// the dominant axis at the block's acceleration.
double first_step_s(Steps a, Steps b, const MachineSettings& s) {
  const long n = std::max({std::labs(b.x - a.x), std::labs(b.y - a.y), std::labs(b.z - a.z)});
  if (n == 0) return 0;
  return std::sqrt(2 * length_mm(a, b, s) / static_cast<double>(n) / block_accel(a, b, s));
}

long sign(long v) { return (v > 0) - (v < 0); }

// q follows p on grbl's straight move s -> e: each axis one step at most, towards e and
// not past it, within one step of the ideal line (the stepper's Bresenham rounding).
bool next_step_on(Steps p, Steps q, Steps s, Steps e) {
  const long P[3] = {p.x, p.y, p.z}, Q[3] = {q.x, q.y, q.z}, S[3] = {s.x, s.y, s.z}, E[3] = {e.x, e.y, e.z};
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    const long d = Q[i] - P[i], D = E[i] - S[i];
    if (std::labs(d) > 1 || (d != 0 && sign(d) != sign(D)) || std::labs(Q[i] - S[i]) > std::labs(D)) return false;
    if (std::labs(D) > std::labs(E[k] - S[k])) k = i;
  }
  const double f = static_cast<double>(Q[k] - S[k]) / static_cast<double>(E[k] - S[k]);
  for (int i = 0; i < 3; ++i)
    if (std::abs(static_cast<double>(Q[i] - S[i]) - f * static_cast<double>(E[i] - S[i])) > 1.0 + 1e-9) return false;
  return true;
}

// Walks the step log block by block (see firmware_record.hpp).
class StepWalker {
 public:
  explicit StepWalker(const StepLog& log) : log_(log) {}
  Steps pos() const { return pos_; }
  bool stalled() const { return stalled_; }
  size_t next_step() const { return i_; }
  // Steps from `limit` on belong to a later epoch; moves on to `from` (the steps skipped
  // are returned: no block explained them).
  size_t start_epoch(size_t from, size_t limit) {
    size_t skipped = 0;
    for (; i_ < from && i_ < log_.steps.size(); ++skipped) pos_ = log_.steps[i_++].pos;
    limit_ = limit;
    stalled_ = false;
    return skipped;
  }

  // Advances along start -> end as far as the log shows. O(steps taken).
  ExecutedBlock run(Steps start, Steps end) {
    ExecutedBlock b;
    b.start = b.stop = start;
    b.planned.end = end;
    b.steps_from = b.steps_to = i_;
    if (stalled_ || !(pos_ == start)) {
      stalled_ = true;
      return b;
    }
    take_spindle_events();  // pen changes come between blocks
    const double duty = duty_;
    while (i_ < std::min(limit_, log_.steps.size()) && !(pos_ == end)) {
      // The pen output may change in mid-block: a feed hold lifts and lowers it, and a
      // sync line that a hold let through early (grbl's wait ends in Hold as the planner
      // empties) switches it while the last segments still run. Counted, not a stop.
      take_spindle_events();
      if (!next_step_on(pos_, log_.steps[i_].pos, start, end)) break;
      b.steps_pen_changed += duty_ != duty;
      pos_ = log_.steps[i_++].pos;
    }
    b.steps_to = i_;
    b.stop = pos_;
    if (i_ > b.steps_from) {
      b.duty = duty;
      b.t_start = log_.steps[b.steps_from].t;
    }
    if (pos_ == end) {
      b.run = ExecutedBlock::Run::Complete;
    } else {
      b.run = i_ > b.steps_from ? ExecutedBlock::Run::Partial : ExecutedBlock::Run::NotRun;
      stalled_ = true;  // the rest of the epoch never ran
    }
    return b;
  }

 private:
  bool spindle_before(size_t step) const { return m_ < log_.spindle.size() && log_.spindle[m_].steps_before <= step; }
  void take_spindle_events() {
    while (spindle_before(i_)) duty_ = log_.spindle[m_++].duty;
  }
  const StepLog& log_;
  size_t i_ = 0, m_ = 0, limit_ = std::numeric_limits<size_t>::max();
  Steps pos_;
  double duty_ = 0;
  bool stalled_ = false;
};

// Block times and rests, once every block of the session is walked: a block began at
// rest if nothing moved for longer than a stop and restart take (two first steps) plus
// grbl's idle lock, which it waits out whenever its planner empties.
void time_blocks(SessionRecord& r, const MachineSettings& s) {
  const StepLog& L = r.step_log;
  long prev = -1;  // the last block that moved
  for (size_t k = 0; k < r.blocks.size(); ++k) {
    ExecutedBlock& b = r.blocks[k];
    if (b.steps_to == b.steps_from) continue;
    const double t1 = first_step_s(b.start, b.planned.end, s);
    bool from_rest = true;
    if (prev >= 0) {
      ExecutedBlock& p = r.blocks[static_cast<size_t>(prev)];
      const double gap = L.steps[b.steps_from].t - L.steps[p.steps_to - 1].t;
      const double t0 = first_step_s(p.start, p.planned.end, s);
      from_rest = gap > t0 + t1 + 0.2e-3 * std::min(s.idle_lock_ms, 25.0) || p.epoch != b.epoch;
      if (from_rest && p.run == ExecutedBlock::Run::Complete) {
        p.rest_after = true;
        p.t_end = L.steps[p.steps_to - 1].t + t0;
        if (p.epoch == b.epoch) r.rests.push_back({static_cast<size_t>(prev), p.t_end, L.steps[b.steps_from].t - t1});
      }
    }
    b.t_start = L.steps[b.steps_from].t - (from_rest ? t1 : 0);
    prev = static_cast<long>(k);
  }
  if (prev >= 0) {  // the last block that moved ends at rest, unless a cut stopped it
    ExecutedBlock& p = r.blocks[static_cast<size_t>(prev)];
    if (p.run == ExecutedBlock::Run::Complete) {
      p.rest_after = true;
      p.t_end = L.steps[p.steps_to - 1].t + first_step_s(p.start, p.planned.end, s);
    }
  }
}

}  // namespace

bool status_position(const std::string& text, const MachineSettings& s, Steps& out) {
  const size_t at = text.find("MPos:");
  double v[3];
  if (text.empty() || text[0] != '<' || at == std::string::npos ||
      std::sscanf(text.c_str() + at + 5, "%lf,%lf,%lf", &v[0], &v[1], &v[2]) != 3)
    return false;
  out = {std::lround(v[0] * s.steps_per_mm[0]), std::lround(v[1] * s.steps_per_mm[1]), std::lround(v[2] * s.steps_per_mm[2])};
  return true;
}

namespace {

// The first step index >= from after which the machine stands within `slack` steps of p
// on every axis (from itself if it stands there already); npos if none.
size_t first_at(const StepLog& L, size_t from, Steps p, long slack = 0) {
  for (size_t i = from; i <= L.steps.size(); ++i) {
    const Steps q = i == 0 ? Steps{} : L.steps[i - 1].pos;
    if (std::labs(q.x - p.x) <= slack && std::labs(q.y - p.y) <= slack && std::labs(q.z - p.z) <= slack) return i;
  }
  return std::string::npos;
}

// Like first_at, but only where the motors then stand still for at least `still_s`
// simulated seconds (or step no more): where a reset stopped them. A path that passes the
// same point twice (a tree drawn back along its edges) would otherwise place the reset at
// the earlier pass. npos if no such place.
size_t stop_at(const StepLog& L, size_t from, Steps p, long slack, double still_s) {
  for (size_t i = from; i <= L.steps.size(); ++i) {
    const Steps q = i == 0 ? Steps{} : L.steps[i - 1].pos;
    if (std::labs(q.x - p.x) > slack || std::labs(q.y - p.y) > slack || std::labs(q.z - p.z) > slack) continue;
    const double t = i == 0 ? 0 : L.steps[i - 1].t;
    if (i == L.steps.size() || L.steps[i].t - t >= still_s) return i;
  }
  return std::string::npos;
}

Steps minus(Steps a, Steps b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Steps plus(Steps a, Steps b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

// Where a reset falls in the step log (the index of the first step after it; npos where the
// status reports do not tell), and grbl's position less the motors' from then on.
struct ResetPlace {
  size_t step = std::string::npos;
  Steps offset;
};

// Every reset of the session after the boot (see build_session). grbl counts a step in its
// position one stepper interrupt before the pin pulses it, and a reset in between drops
// the pulse: its MPos is then a step ahead of the motors on that axis, for good (grbl's
// "position lost" after ALARM:3). O(device lines + steps).
std::vector<ResetPlace> reset_steps(const StepLog& L, const std::vector<SessionEvent>& events,
                                    const std::vector<DeviceLine>& device, const MachineSettings& s) {
  std::vector<ResetPlace> out;
  size_t anchor = 0, scanned = 0;  // step index of the last status report placed; device lines read
  Steps off;                       // grbl's position less the motors' in the current epoch
  bool booted = false;
  for (const SessionEvent& ev : events) {
    if (ev.kind != SessionEvent::Kind::Reset) continue;
    for (; scanned < ev.device && scanned < device.size(); ++scanned) {
      Steps p;
      if (!status_position(device[scanned].text, s, p)) continue;
      const size_t i = first_at(L, anchor, minus(p, off));
      if (i != std::string::npos) anchor = i;
    }
    if (!booted) {  // the boot banner: the log begins there
      booted = true;
      continue;
    }
    // The first report after it; past another banner if one came first (a host that
    // answers an outside reset's ALARM:3 with a reset of its own: no move in between).
    ResetPlace at;
    for (size_t k = ev.device + 1; k < device.size(); ++k) {
      Steps p;
      if (!status_position(device[k].text, s, p)) continue;
      // Where the motors stood still after it (ALARM until the host unlocks: half a second
      // or more), else, as before, the first place they were there.
      constexpr double kResetStillS = 0.5;
      at.step = stop_at(L, anchor, minus(p, off), 0, kResetStillS);
      if (at.step == std::string::npos) at.step = stop_at(L, anchor, minus(p, off), 1, kResetStillS);
      if (at.step == std::string::npos) at.step = first_at(L, anchor, minus(p, off));
      if (at.step == std::string::npos) at.step = first_at(L, anchor, minus(p, off), 1);
      if (at.step != std::string::npos) off = minus(p, at.step == 0 ? Steps{} : L.steps[at.step - 1].pos);
      break;
    }
    at.offset = off;
    out.push_back(at);
    if (at.step != std::string::npos) anchor = at.step;
  }
  return out;
}

// What grbl ran of the lines a reset flushed while they were on the wire: replies[i] (the
// i-th reply after the reset) answered the tail of flushed line k (from a word on, or
// whole) for i = 0 and line k + i after it. Of every k and tail, the first under which
// every answered move is one the step log shows whole, taking the most steps; the last
// lines first, as the ones in flight are the newest. O(flushed x words x replies x steps).
std::vector<std::string> in_flight(const std::vector<const HostLine*>& replies, const std::vector<HostLine>& lines,
                                   const GcodeInterpreter& g, const StepWalker& walk, Steps off) {
  const std::vector<size_t>& flushed = replies[0]->fragment_of;
  std::vector<std::string> best;
  size_t best_steps = 0;
  for (size_t k = flushed.size(); k-- > 0;) {
    if (k + replies.size() > flushed.size()) continue;
    const std::string head = grbl_line_filter(lines[flushed[k]].text);
    for (size_t p = 0; p < head.size(); ++p) {
      if (!std::isalpha(static_cast<unsigned char>(head[p]))) continue;
      std::vector<std::string> texts;
      GcodeInterpreter trial = g;
      StepWalker w = walk;
      bool fits = true;
      for (size_t i = 0; i < replies.size() && fits; ++i) {
        texts.push_back(i == 0 ? head.substr(p) : grbl_line_filter(lines[flushed[k + i]].text));
        if (replies[i]->reply != HostLine::Reply::Ok) continue;  // grbl refused it: it changed nothing
        try {
          const LineEffect e = trial.feed(texts.back());
          if (e.motion && !(e.from == e.to))
            fits = w.run(minus(e.from, off), minus(e.to, off)).run == ExecutedBlock::Run::Complete;
        } catch (const std::exception&) {
          fits = false;
        }
      }
      if (fits && (best.empty() || w.next_step() > best_steps)) {
        best = texts;
        best_steps = w.next_step();
      }
    }
  }
  return best;
}

}  // namespace

StepLog parse_step_log(const std::string& text) {
  StepLog log;
  const char* p = text.c_str();
  const char* end = p + text.size();
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
    if (!nl) break;  // a line cut short (the log is taken while grbl_avr writes it)
    std::string line(p, nl);
    p = nl + 1;
    if (line.empty() || line[0] == '#') continue;
    double t = 0;
    long x = 0, y = 0, z = 0;
    char axes[8];
    if (line[0] == 'P' && std::sscanf(line.c_str(), "P %lf %7s %ld %ld %ld", &t, axes, &x, &y, &z) == 5) {
      log.steps.push_back({t, {x, y, z}});
    } else if (line[0] == 'M') {
      double duty = 0;
      if (std::sscanf(line.c_str(), "M %lf duty=%lf", &t, &duty) == 2) log.spindle.push_back({t, duty, log.steps.size()});
    } else if (line[0] == 'E' && std::sscanf(line.c_str(), "E %lf %ld %ld %ld", &t, &x, &y, &z) == 4) {
      log.ended = true;
      log.t_end = t;
      log.end_pos = {x, y, z};
    }
  }
  return log;
}

std::string describe(const SessionRecord& s, const MachineSettings& m) {
  std::string out = "session " + std::to_string(s.index) + (s.power_cut ? " (power cut)" : "") + ": " +
                    std::to_string(s.blocks.size()) + " blocks, " + std::to_string(s.step_log.steps.size()) + " steps\n";
  char b[200];
  const char* run[] = {"not run", "partial", "complete"};
  for (size_t k = 0; k < s.blocks.size(); ++k) {
    const ExecutedBlock& x = s.blocks[k];
    std::snprintf(b, sizeof b, "%4zu e%d to %8.2f %8.2f %6.2f%s duty %5.3f %-8s start %9.5f end %9.5f%s", k, x.epoch,
                  x.planned.end.x / m.steps_per_mm[0], x.planned.end.y / m.steps_per_mm[1],
                  x.planned.end.z / m.steps_per_mm[2], x.planned.rapid ? " G0" : " G1", x.duty,
                  run[static_cast<int>(x.run)], x.t_start, x.t_end, x.rest_after ? " rest" : "");
    out += b;
    if (x.steps_pen_changed) out += " (" + std::to_string(x.steps_pen_changed) + " steps with the pen changed)";
    out += "\n";
    continue;
    out += b;
  }
  for (const std::string& p : s.problems) out += "  problem: " + p + "\n";
  return out;
}

SessionRecord build_session(const StepLog& log, const std::vector<HostLine>& lines, const std::vector<SessionEvent>& events,
                            const MachineSettings& s, const std::vector<DeviceLine>& device) {
  SessionRecord r;
  r.step_log = log;
  r.events = events;
  const std::vector<ResetPlace> resets = reset_steps(r.step_log, events, device, s);
  Steps off;  // grbl's position less the motors' (see reset_steps)
  GcodeInterpreter g(s, PenRule::servo());  // the pen rule plays no part in where grbl moves
  StepWalker walk(r.step_log);
  int epoch = -1;
  for (const SessionEvent& ev : events) {
    if (ev.kind == SessionEvent::Kind::Reset) {
      ++epoch;
      const size_t e = static_cast<size_t>(epoch);
      const bool placed = e == 0 || (e - 1 < resets.size() && resets[e - 1].step != std::string::npos);
      const size_t from = e > 0 && placed ? resets[e - 1].step : 0;
      const size_t limit = e < resets.size() && resets[e].step != std::string::npos ? resets[e].step
                                                                                     : std::numeric_limits<size_t>::max();
      if (!placed) r.problems.push_back("reset " + std::to_string(e) + ": no status report placed it in the step log");
      if (e > 0 && e - 1 < resets.size()) off = resets[e - 1].offset;
      if (const size_t skipped = walk.start_epoch(from, limit))
        r.problems.push_back(std::to_string(skipped) + " steps before reset " + std::to_string(e) + " follow no planned block");
      r.epoch_start.push_back(plus(walk.pos(), off));  // grbl keeps its position across a soft reset
      g.reset(plus(walk.pos(), off));
      continue;
    }
    const HostLine& l = lines[ev.line];
    const bool first_in_flight = !l.fragment_of.empty() && &ev != events.data() && (&ev - 1)->kind == SessionEvent::Kind::Reset;
    if (first_in_flight) {
      std::vector<const HostLine*> replies;  // this reset's run of replies to lines in flight
      std::vector<size_t> at;
      for (const SessionEvent* f = &ev; f != events.data() + events.size() && f->kind == SessionEvent::Kind::Line &&
                                        !lines[f->line].fragment_of.empty(); ++f) {
        replies.push_back(&lines[f->line]);
        at.push_back(f->line);
      }
      const std::vector<std::string> texts = in_flight(replies, lines, g, walk, off);
      if (texts.empty()) r.problems.push_back("what grbl ran after reset " + std::to_string(epoch) + " is no run of flushed lines");
      for (size_t i = 0; i < texts.size(); ++i) r.fragment_text.push_back({at[i], texts[i]});
    }
    if (l.reply != HostLine::Reply::Ok) continue;
    const std::string text = r.text_ran(ev.line, lines);
    LineEffect e;
    try {
      e = g.feed(text);
    } catch (const std::exception& ex) {
      r.problems.push_back("line `" + text + "`: " + ex.what());
      continue;
    }
    if (!e.motion || e.from == e.to) continue;
    // The walk is in the motors' steps; the block, as grbl planned it, in grbl's.
    ExecutedBlock b = walk.run(minus(e.from, off), minus(e.to, off));
    b.start = e.from;
    b.planned.end = e.to;
    b.stop = plus(b.stop, off);
    b.planned.rapid = e.rapid;
    b.epoch = epoch;
    r.blocks.push_back(b);
  }
  if (walk.next_step() < r.step_log.steps.size())
    r.problems.push_back(std::to_string(r.step_log.steps.size() - walk.next_step()) + " steps after step " +
                         std::to_string(walk.next_step()) + " follow no planned block");
  time_blocks(r, s);
  return r;
}

namespace {

std::string where(const SessionRecord& s, size_t line, const HostLine& l) {
  return "session " + std::to_string(s.index) + " line " + std::to_string(line) + " `" + l.text + "`";
}

std::string str(Steps p) { return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z); }

bool duty_down(double duty, const PenRule& rule, const MachineSettings& m) {
  return duty * m.spindle_max > rule.servo_up_s + m.spindle_max / 255;
}

// The block a move planned must start and end where the line does; for a servo pen the
// firmware's own pen output while it ran must agree with the pen the lines set.
void check_block(const ExecutedBlock& b, size_t index, const LineEffect& e, bool pen_down, const PenRule& rule,
                 const MachineSettings& m, const std::string& at, Interpretation& out) {
  if (!(b.start == e.from) || !(b.planned.end == e.to))
    out.inconsistencies.push_back(at + ": block " + std::to_string(index) + " runs " + str(b.start) + " to " +
                                  str(b.planned.end) + ", the line " + str(e.from) + " to " + str(e.to));
  if (rule.kind == PenRule::Kind::Servo && b.duty >= 0 && duty_down(b.duty, rule, m) != pen_down)
    out.inconsistencies.push_back(at + ": the firmware's pen output (duty " + std::to_string(b.duty) +
                                  ") disagrees with the pen the lines set");
}

// Each rest with more of the epoch to come: at a line that makes grbl empty its planner,
// or starved (the next move had not arrived).
void classify_rests(const SessionRecord& s, const std::vector<bool>& sync_after, Interpretation& out) {
  size_t last_sync = 0;
  for (const RestEvent& rest : s.rests) {
    if (rest.block >= sync_after.size()) continue;
    if (sync_after[rest.block]) {
      ++out.rests_at_sync;
      last_sync = rest.block + 1;
    } else {
      const double still = std::max(0.0, rest.t_resume - rest.t_stop);
      ++out.rests_starved;
      out.starved_s += still;
      out.starved.push_back({s.index, rest.block, rest.block + 1 - last_sync, still});
    }
  }
}

// One session: the lines grbl answered, in order, each move paired with the next block
// grbl planned (grbl plans exactly one block per move of at least one step).
void interpret_session(const FirmwareRecord& r, const SessionRecord& s, const PenRule& rule, Steps offset,
                       Interpretation& out) {
  GcodeInterpreter g(r.settings, rule);
  g.reset({});
  MarkCollector pen(rule, r.settings.steps_per_mm[2]);
  std::vector<long> block_line(s.blocks.size(), -1);
  std::vector<bool> sync_after(s.blocks.size(), false);
  int epoch = -1;
  size_t cursor = 0;  // next block
  Steps physical;     // where the machine is (where the last move that ran stopped)
  for (const std::string& p : s.problems) out.inconsistencies.push_back("session " + std::to_string(s.index) + ": " + p);
  for (const SessionEvent& ev : s.events) {
    if (ev.kind == SessionEvent::Kind::Reset) {
      ++epoch;
      if (static_cast<size_t>(epoch) < s.epoch_start.size()) physical = s.epoch_start[static_cast<size_t>(epoch)];
      pen.pen(false, physical);  // the spindle stops at a reset
      g.reset(physical);
      continue;
    }
    const HostLine& l = r.lines[ev.line];
    if (l.reply != HostLine::Reply::Ok) continue;
    const std::string text = s.text_ran(ev.line, r.lines);
    LineEffect e;
    try {
      e = g.feed(text);
    } catch (const std::exception&) {
      continue;  // build_session reported it
    }
    if ((e.sync || e.system) && cursor > 0) sync_after[cursor - 1] = true;
    if (e.pen_before >= 0) pen.pen(e.pen_before == 1, physical);
    if (e.motion && !(e.from == e.to)) {
      if (cursor >= s.blocks.size()) {
        out.inconsistencies.push_back(where(s, ev.line, l) + ": a move with no planner block");
        continue;
      }
      const ExecutedBlock& b = s.blocks[cursor];
      check_block(b, cursor, e, g.pen_down(), rule, r.settings, where(s, ev.line, l), out);
      out.steps_pen_changed += b.steps_pen_changed;
      block_line[cursor] = static_cast<long>(ev.line);
      if (b.run != ExecutedBlock::Run::NotRun) {
        pen.move(b.start, b.stop, b.run == ExecutedBlock::Run::Complete);
        physical = b.stop;
      }
      ++cursor;
    }
    if (e.pen_after >= 0) pen.pen(e.pen_after == 1, physical);
  }
  pen.finish();
  for (Mark m : pen.marks()) {
    out.marks.push_back({m.kind, plus(m.a, offset), plus(m.b, offset)});
    if (m.kind != Mark::Kind::Dot) out.pen_down_mm += length_mm(m.a, m.b, r.settings);
  }
  classify_rests(s, sync_after, out);
  out.block_line.push_back(std::move(block_line));
}

// The first and the last block of a session that moved (nulls when none did).
std::pair<const ExecutedBlock*, const ExecutedBlock*> executed_span(const SessionRecord& s) {
  const ExecutedBlock *first = nullptr, *last = nullptr;
  for (const ExecutedBlock& b : s.blocks)
    if (b.run != ExecutedBlock::Run::NotRun) {
      if (!first) first = &b;
      last = &b;
    }
  return {first, last};
}

const SessionRecord* last_session_that_moved(const FirmwareRecord& r, int session) {
  const SessionRecord* s = nullptr;
  for (const SessionRecord& c : r.sessions)
    if (executed_span(c).first && (session < 0 || c.index == session)) s = &c;
  return s;
}

}  // namespace

Interpretation interpret(const FirmwareRecord& r, const PenRule& rule, const std::vector<Steps>& offsets) {
  Interpretation out;
  for (size_t i = 0; i < r.sessions.size(); ++i)
    interpret_session(r, r.sessions[i], rule, i < offsets.size() ? offsets[i] : Steps{}, out);
  return out;
}

double firmware_plot_seconds(const FirmwareRecord& r, const PenRule& rule, int session) {
  const SessionRecord* s = last_session_that_moved(r, session);
  if (!s) return 0;
  const auto [first, last] = executed_span(*s);
  const Steps e = last->planned.end;
  const bool pen_up = rule.kind == PenRule::Kind::ZAxis ? e.z >= rule.z_down_below_mm * r.settings.steps_per_mm[2]
                                                        : !duty_down(last->duty, rule, r.settings);
  const bool home = pen_up && e.x == 0 && e.y == 0 && last != first && last->t_start >= 0;
  const double end = home ? last->t_start : last->t_end;
  return end - first->t_start;
}

double firmware_motion_seconds(const FirmwareRecord& r, int session) {
  const SessionRecord* s = last_session_that_moved(r, session);
  if (!s) return 0;
  const auto [first, last] = executed_span(*s);
  if (last->t_end < 0 || first->t_start < 0) return -1;
  return last->t_end - first->t_start;
}

}  // namespace firmware
