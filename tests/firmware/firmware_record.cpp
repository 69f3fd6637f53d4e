#include "firmware/firmware_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace firmware {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string l;
  while (std::getline(in, l)) out.push_back(l);
  return out;
}

double length_mm(Steps a, Steps b, const MachineSettings& s) {
  double dx = (b.x - a.x) / s.steps_per_mm[0], dy = (b.y - a.y) / s.steps_per_mm[1], dz = (b.z - a.z) / s.steps_per_mm[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// grbl's block acceleration: each axis limited to its own $12x (planner.c
// limit_value_by_axis_maximum).
double block_accel(Steps a, Steps b, const MachineSettings& s) {
  const double d[3] = {(b.x - a.x) / s.steps_per_mm[0], (b.y - a.y) / s.steps_per_mm[1], (b.z - a.z) / s.steps_per_mm[2]};
  double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double acc = kInf;
  for (int i = 0; i < 3; ++i)
    if (d[i] != 0) acc = std::min(acc, s.accel_mm_s2[i] * len / std::abs(d[i]));
  return std::isfinite(acc) ? acc : s.accel_mm_s2[0];
}

// p lies on the straight move a -> b, allowing for the stepper's Bresenham rounding.
bool on_segment(Steps p, Steps a, Steps b) {
  const double d[3] = {double(b.x - a.x), double(b.y - a.y), double(b.z - a.z)};
  const double q[3] = {double(p.x - a.x), double(p.y - a.y), double(p.z - a.z)};
  double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (dd == 0) return p == a;
  double t = (q[0] * d[0] + q[1] * d[1] + q[2] * d[2]) / dd;
  if (t < -1e-9 - 1.0 / std::sqrt(dd) || t > 1 + 1.0 / std::sqrt(dd)) return false;
  double e = 0;
  for (int i = 0; i < 3; ++i) e += (q[i] - t * d[i]) * (q[i] - t * d[i]);
  return e <= 1.5 * 1.5;
}

// Which block each step-log line lies on: the planned path is followed forward only (a
// line may skip short blocks; a point the path passes twice is taken at the earlier pass
// until a later line shows otherwise). -1: on no block within reach.
// O(lines x 2000) at worst, O(lines + blocks) when every line lies on the path.
std::vector<long> align_lines(const std::vector<ExecutedBlock>& b, size_t first, size_t last, const std::vector<StepLine>& l,
                              size_t lo, size_t hi) {
  std::vector<long> at(hi - lo, -1);
  if (first >= last) return at;
  size_t k = first;
  for (size_t i = lo; i < hi; ++i) {
    const Steps p = l[i].pos;
    for (size_t j = k; j < last && j < k + 2000; ++j)
      if (on_segment(p, b[j].start, b[j].planned.end)) {
        k = j;
        at[i - lo] = static_cast<long>(j);
        break;
      }
  }
  return at;
}

// The motion of blocks [first, last) ended at `stop` (a reset's position, or the last
// line before a power cut), on block `from` or later. Returns false if `stop` is on none.
bool settle(std::vector<ExecutedBlock>& b, size_t from, size_t last, Steps stop) {
  for (size_t j = from; j < last; ++j) {
    const bool at_end = stop == b[j].planned.end;
    if (!at_end && !on_segment(stop, b[j].start, b[j].planned.end)) continue;
    if (!at_end) {
      b[j].run = stop == b[j].start ? ExecutedBlock::Run::NotRun : ExecutedBlock::Run::Partial;
      b[j].stop = stop;
    }
    for (size_t k = j + 1; k < last; ++k) {
      b[k].run = ExecutedBlock::Run::NotRun;
      b[k].stop = b[k].start;
    }
    return true;
  }
  return false;
}

// Path length (mm) from `pos` on block `on` to the end of block `to`.
double path_left(const std::vector<ExecutedBlock>& b, long on, size_t to, Steps pos, const MachineSettings& s) {
  if (on < 0 || static_cast<size_t>(on) > to) return length_mm(pos, b[to].planned.end, s);
  double d = length_mm(pos, b[static_cast<size_t>(on)].planned.end, s);
  for (size_t i = static_cast<size_t>(on) + 1; i <= to; ++i) d += length_mm(b[i].start, b[i].planned.end, s);
  return d;
}

// The machine decelerates to rest over what the planner had prepared: t = sqrt(2 d / a).
double rest_time(double t_emptied, double d_mm, const ExecutedBlock& last, const MachineSettings& s) {
  return t_emptied + std::sqrt(2 * d_mm / block_accel(last.start, last.planned.end, s));
}

}  // namespace

std::string describe(const SessionRecord& s, const MachineSettings& m) {
  std::string out = "session " + std::to_string(s.index) + (s.power_cut ? " (power cut)" : "") + ": " +
                    std::to_string(s.blocks.size()) + " blocks\n";
  char b[200];
  const char* run[] = {"not run", "partial", "complete"};
  for (size_t k = 0; k < s.blocks.size(); ++k) {
    const ExecutedBlock& x = s.blocks[k];
    std::snprintf(b, sizeof b, "%4zu e%d to %8.2f %8.2f %6.2f flags %2u S%-5.0f %-8s start %9.5f end %9.5f%s\n", k, x.epoch,
                  x.planned.end.x / m.steps_per_mm[0], x.planned.end.y / m.steps_per_mm[1],
                  x.planned.end.z / m.steps_per_mm[2], x.planned.condition, x.planned.spindle,
                  run[static_cast<int>(x.run)], x.t_start, x.t_end, x.rest_after ? " rest" : "");
    out += b;
  }
  return out;
}

BlockLog parse_block_log(const std::string& text) {
  BlockLog bl;
  for (const std::string& l : split_lines(text)) {
    if (l.empty()) continue;
    ResetMark r;
    if (std::sscanf(l.c_str(), "# reset at %lf pos %ld, %ld, %ld", &r.t, &r.pos.x, &r.pos.y, &r.pos.z) == 4) {
      bl.resets.push_back(r);
      bl.epochs.emplace_back();
      continue;
    }
    if (l.rfind("# rx drop", 0) == 0) {
      ++bl.rx_drops;
      continue;
    }
    if (l[0] == '#') continue;
    PlannedBlock b;
    if (std::sscanf(l.c_str(), "%ld, %ld, %ld, %lf, %u, %lf, %lf", &b.end.x, &b.end.y, &b.end.z, &b.entry_speed_sqr,
                    &b.condition, &b.spindle, &b.mm_logged) != 7)
      continue;
    // The logger walks grbl's ring buffer from the last block it printed to the head; when
    // it runs between a reset's plan_reset() (which zeroes the buffer and moves the head to
    // 0) and the banner that tells it of the reset, it prints the zeroed slots it passes.
    // grbl never plans a block without steps, so a zeroed one is that and nothing else.
    if (b.mm_logged == 0 && b.condition == 0 && b.spindle == 0 && b.entry_speed_sqr == 0) {
      ++bl.zeroed_slots;
      continue;
    }
    if (bl.epochs.empty()) {  // a log that starts without its boot line
      bl.resets.push_back({});
      bl.epochs.emplace_back();
    }
    bl.epochs.back().push_back(b);
  }
  return bl;
}

StepLog parse_step_log(const std::string& text, double sample_s, bool moving_at_end, bool exit_line) {
  StepLog sl;
  for (const std::string& l : split_lines(text)) {
    StepLine x;
    if (!l.empty() && l[0] != '#' &&
        std::sscanf(l.c_str(), "%lf %ld, %ld, %ld, %d", &x.t, &x.pos.x, &x.pos.y, &x.pos.z, &x.spindle_pwm) == 5)
      sl.lines.push_back(x);
  }
  if (exit_line && !sl.lines.empty()) sl.lines.pop_back();
  const double gap = 1.5 * sample_s;
  for (size_t i = 0; i + 1 < sl.lines.size(); ++i)
    if (sl.lines[i + 1].t - sl.lines[i].t > gap)
      sl.empties.push_back({sl.lines[i].t, sl.lines[i].pos, sl.lines[i + 1].t, sl.lines[i + 1].pos});
  if (!moving_at_end && !sl.lines.empty()) sl.empties.push_back({sl.lines.back().t, sl.lines.back().pos, -1, {}});
  sl.ends_moving = moving_at_end;
  return sl;
}

namespace {

size_t line_at(const std::vector<StepLine>& l, double t) {
  return static_cast<size_t>(std::lower_bound(l.begin(), l.end(), t, [](const StepLine& x, double v) { return x.t < v; }) -
                             l.begin());
}

// Rests of one epoch: where the planner ran dry, which block the machine then stopped at
// (or was still on when the next block came), and when.
void find_rests(SessionRecord& r, size_t first, size_t last, size_t lo, size_t hi, const std::vector<long>& at,
                const MachineSettings& s) {
  const std::vector<StepLine>& L = r.step_log.lines;
  for (const PlannerEmpty& e : r.step_log.empties) {
    size_t i = line_at(L, e.t_emptied);
    if (i < lo || i >= hi) continue;
    const long on = at[i - lo];
    const size_t from = on < 0 ? first : static_cast<size_t>(on);
    const bool resumed = e.t_resumed >= 0 && line_at(L, e.t_resumed) < hi;
    // The machine stopped at the end of the last block that ran, or where it moved off again.
    size_t kr = last;
    bool full = false;
    for (size_t j = from; j < last; ++j) {
      if (r.blocks[j].run == ExecutedBlock::Run::NotRun) break;
      if (resumed ? e.pos_resumed == r.blocks[j].planned.end : r.blocks[j].run == ExecutedBlock::Run::Complete &&
                                                                 (j + 1 == last || r.blocks[j + 1].run == ExecutedBlock::Run::NotRun)) {
        kr = j;
        full = true;
        break;
      }
      if (resumed && on_segment(e.pos_resumed, r.blocks[j].start, r.blocks[j].planned.end)) {
        kr = j;
        break;
      }
    }
    if (kr == last) {
      if (resumed) r.ambiguous_cut = true;
      continue;
    }
    ExecutedBlock& b = r.blocks[kr];
    double t_stop = -1;
    if (full) {
      b.rest_after = true;
      b.t_end = t_stop = rest_time(e.t_emptied, path_left(r.blocks, on, kr, e.pos_emptied, s), b, s);
    }
    if (resumed && kr + 1 < last) {
      r.rests.push_back({kr, full, t_stop, e.t_resumed});
      if (full) r.blocks[kr + 1].t_start = e.t_resumed;
    }
  }
}

}  // namespace

// O(blocks + step-log lines), the alignment aside.
SessionRecord build_session(const BlockLog& bl, const StepLog& sl, const MachineSettings& s, bool power_cut,
                            double cut_idle_wall_s) {
  SessionRecord r;
  r.power_cut = power_cut;
  r.cut_idle_wall_s = cut_idle_wall_s;
  r.block_log = bl;
  r.step_log = sl;
  const std::vector<StepLine>& L = r.step_log.lines;
  for (size_t e = 0; e < bl.epochs.size(); ++e) {
    const double t_next = e + 1 < bl.resets.size() ? bl.resets[e + 1].t : kInf;
    Steps start = bl.resets[e].pos;
    const size_t first = r.blocks.size();
    for (const PlannedBlock& p : bl.epochs[e]) {
      ExecutedBlock x;
      x.planned = p;
      x.start = start;
      x.stop = p.end;
      x.epoch = static_cast<int>(e);
      x.run = ExecutedBlock::Run::Complete;  // unless the epoch ended early (below)
      start = p.end;
      r.blocks.push_back(x);
    }
    const size_t last = r.blocks.size();
    const size_t lo = line_at(L, bl.resets[e].t), hi = line_at(L, t_next);
    const std::vector<long> at = align_lines(r.blocks, first, last, L, lo, hi);
    long reached = static_cast<long>(first);
    for (long k : at) reached = std::max(reached, k);
    if (e + 1 < bl.resets.size()) {  // a reset: grbl stopped where its reset line says
      if (!settle(r.blocks, static_cast<size_t>(reached), last, bl.resets[e + 1].pos)) r.ambiguous_cut = true;
    } else if (power_cut) {
      if (hi > lo && r.step_log.ends_moving) {
        if (!settle(r.blocks, static_cast<size_t>(reached), last, L[hi - 1].pos)) r.ambiguous_cut = true;
      } else if (hi > lo && cut_idle_wall_s < 0.3) {
        r.ambiguous_cut = true;  // cut while the last prepared segments may still have been running
      } else if (hi == lo && first < last) {
        settle(r.blocks, first, last, bl.resets[e].pos);  // planned, never started
      }
    }
    if (hi > lo && first < last && L[lo].pos == r.blocks[first].start) r.blocks[first].t_start = L[lo].t;
    find_rests(r, first, last, lo, hi, at, s);
  }
  return r;
}

namespace {

std::string where(const SessionRecord& s, size_t line, const HostLine& l) {
  return "session " + std::to_string(s.index) + " line " + std::to_string(line) + " `" + l.text + "`";
}

Steps plus(Steps a, Steps o) { return {a.x + o.x, a.y + o.y, a.z + o.z}; }

std::string str(Steps p) { return std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z); }

// The block grbl planned for a move must start and end where the line does, and carry the
// pen state (servo: spindle flags and S) the line ran with.
void check_block(const ExecutedBlock& b, size_t index, const LineEffect& e, bool pen_down, const PenRule& rule,
                 const std::string& at, Interpretation& out) {
  if (!(b.start == e.from) || !(b.planned.end == e.to))
    out.inconsistencies.push_back(at + ": block " + std::to_string(index) + " runs " + str(b.start) + " to " +
                                  str(b.planned.end) + ", the line " + str(e.from) + " to " + str(e.to));
  if (rule.kind == PenRule::Kind::Servo && (b.planned.spindle_on() && b.planned.spindle > rule.servo_up_s) != pen_down)
    out.inconsistencies.push_back(at + ": the block's spindle flags disagree with the pen state");
}

// Each time the planner ran dry with more to come: at a line that makes grbl empty it, or
// starved (the next move had not arrived).
void classify_rests(const SessionRecord& s, const std::vector<bool>& sync_after, Interpretation& out) {
  size_t last_sync = 0;
  for (const RestEvent& rest : s.rests) {
    if (rest.block >= sync_after.size()) continue;
    if (sync_after[rest.block]) {
      ++out.rests_at_sync;
      last_sync = rest.block + 1;
    } else {
      const double still = rest.full_stop ? std::max(0.0, rest.t_resume - rest.t_stop) : 0.0;
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
  std::vector<Mark> marks;
  std::vector<long> block_line(s.blocks.size(), -1);
  std::vector<bool> sync_after(s.blocks.size(), false);
  auto flush_marks = [&] {
    pen.finish();
    for (Mark m : pen.marks()) marks.push_back({m.kind, plus(m.a, offset), plus(m.b, offset)});
    pen = MarkCollector(rule, r.settings.steps_per_mm[2]);
  };
  int epoch = -1;
  size_t cursor = 0;  // next block of the epoch
  auto epoch_end = [&] {
    size_t e = cursor;
    while (e < s.blocks.size() && s.blocks[e].epoch == epoch) ++e;
    return e;
  };
  auto unclaimed = [&] {
    for (size_t e = epoch_end(); cursor < e; ++cursor)
      out.inconsistencies.push_back("session " + std::to_string(s.index) + ": block " + std::to_string(cursor) +
                                    " was planned but no line explains it");
  };
  Steps physical;  // where the machine is (end of the last move that ran)
  for (const SessionEvent& ev : s.events) {
    if (ev.kind == SessionEvent::Kind::Reset) {
      if (epoch >= 0) unclaimed();
      ++epoch;
      // grbl-sim flushes a reset line with the next block it logs: a reset with no move
      // after it may not be in the file yet. grbl keeps its position across a soft reset.
      if (static_cast<size_t>(epoch) < s.block_log.resets.size()) physical = s.block_log.resets[static_cast<size_t>(epoch)].pos;
      pen.pen(false, physical);  // the spindle stops at a reset
      g.reset(physical);
      while (cursor < s.blocks.size() && s.blocks[cursor].epoch < epoch) ++cursor;
      continue;
    }
    const HostLine& l = r.lines[ev.line];
    if (l.reply != HostLine::Reply::Ok) continue;
    LineEffect e;
    try {
      e = g.feed(l.text);
    } catch (const std::exception& ex) {
      out.inconsistencies.push_back(where(s, ev.line, l) + ": " + ex.what());
      continue;
    }
    if (e.sync || e.system) {
      if (cursor > 0 && cursor - 1 < s.blocks.size()) sync_after[cursor - 1] = true;
    }
    if (e.pen_before >= 0) pen.pen(e.pen_before == 1, physical);
    if (e.motion && !(e.from == e.to)) {
      if (cursor >= s.blocks.size() || s.blocks[cursor].epoch != epoch) {
        out.inconsistencies.push_back(where(s, ev.line, l) + ": a move with no planner block");
        continue;
      }
      const ExecutedBlock& b = s.blocks[cursor];
      check_block(b, cursor, e, g.pen_down(), rule, where(s, ev.line, l), out);
      block_line[cursor] = static_cast<long>(ev.line);
      if (b.run != ExecutedBlock::Run::NotRun) {
        pen.move(b.start, b.stop, b.run == ExecutedBlock::Run::Complete);
        physical = b.stop;
      }
      ++cursor;
    }
    if (e.pen_after >= 0) pen.pen(e.pen_after == 1, physical);
  }
  if (epoch >= 0) unclaimed();
  if (epoch + 1 < static_cast<int>(s.block_log.resets.size()))
    out.inconsistencies.push_back("session " + std::to_string(s.index) + ": fewer banners than reset lines in the block log");
  flush_marks();
  out.marks.insert(out.marks.end(), marks.begin(), marks.end());
  classify_rests(s, sync_after, out);
  out.block_line.push_back(std::move(block_line));
}

}  // namespace

Interpretation interpret(const FirmwareRecord& r, const PenRule& rule, const std::vector<Steps>& offsets) {
  Interpretation out;
  for (size_t i = 0; i < r.sessions.size(); ++i)
    interpret_session(r, r.sessions[i], rule, i < offsets.size() ? offsets[i] : Steps{}, out);
  return out;
}

namespace {
// The first and the last block of a session that ran (nulls when none did).
std::pair<const ExecutedBlock*, const ExecutedBlock*> executed_span(const SessionRecord& s) {
  const ExecutedBlock *first = nullptr, *last = nullptr;
  for (const ExecutedBlock& b : s.blocks)
    if (b.run != ExecutedBlock::Run::NotRun) {
      if (!first) first = &b;
      last = &b;
    }
  return {first, last};
}
}  // namespace

double firmware_plot_seconds(const FirmwareRecord& r, const PenRule& rule, int session) {
  const SessionRecord* s = nullptr;
  if (session >= 0) {
    s = &r.sessions.at(static_cast<size_t>(session));
  } else {
    for (const SessionRecord& c : r.sessions)
      for (const ExecutedBlock& b : c.blocks)
        if (b.run != ExecutedBlock::Run::NotRun) s = &c;
  }
  if (!s) return 0;
  const auto [first, last] = executed_span(*s);
  if (!first) return 0;
  const PlannedBlock& p = last->planned;
  bool pen_up = rule.kind == PenRule::Kind::ZAxis ? p.end.z >= rule.z_down_below_mm * r.settings.steps_per_mm[2]
                                                  : !(p.spindle_on() && p.spindle > rule.servo_up_s);
  bool home = pen_up && p.end.x == 0 && p.end.y == 0 && last != first && last->t_start >= 0;
  double end = home ? last->t_start : last->t_end;
  return end - first->t_start;
}

double firmware_motion_seconds(const FirmwareRecord& r, int session) {
  const SessionRecord* s = nullptr;
  for (const SessionRecord& c : r.sessions)
    for (const ExecutedBlock& b : c.blocks)
      if (b.run != ExecutedBlock::Run::NotRun && (session < 0 || c.index == session)) s = &c;
  if (!s) return 0;
  const auto [first, last] = executed_span(*s);
  if (!first || last->t_end < 0 || first->t_start < 0) return -1;
  return last->t_end - first->t_start;
}

}  // namespace firmware
