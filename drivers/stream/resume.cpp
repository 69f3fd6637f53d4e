#include "drivers/stream/resume.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/segments.hpp"
#include "util/error.hpp"

namespace stipplot::io {

namespace {

bool is_gcode_pen_line(const std::string& text) {
  bool xy = false, z = false, pen = false;
  for (const GcodeWord& w : gcode_words(text)) {
    if (w.letter == 'X' || w.letter == 'Y') xy = true;
    if (w.letter == 'Z') z = true;
    if (w.letter == 'S') pen = true;
    if (w.letter == 'M' && (std::lround(w.value) == 3 || std::lround(w.value) == 4 || std::lround(w.value) == 5))
      pen = true;
  }
  return pen || (z && !xy);
}

bool is_dwell_line(const std::string& text) {
  for (const GcodeWord& w : gcode_words(text))
    if (is_dwell(w)) return true;
  return false;
}

bool pen_down_before(const std::vector<JobLine>& L, size_t k) { return k == 0 ? false : L[k - 1].pen_down; }

struct Point {
  double x = 0, y = 0;
};

// Where line k starts: where line k - 1 leaves the pen (machine zero before the first).
Point start_of(const std::vector<JobLine>& L, size_t k) { return k ? Point{L[k - 1].x, L[k - 1].y} : Point{}; }

// A resume point right after the pen went down, before it moved: for a dot, the dot is
// finished by the lift (skip to after its pen-up); for a stroke, start the stroke again
// from its pen-down line.
size_t settle_resume_point(const Job& job, size_t next) {
  const auto& L = job.lines;
  if (!pen_down_before(L, next)) return next;
  size_t d = next;
  while (d > 0 && L[d - 1].pen_down) --d;  // L[d] is the line that put the pen down
  bool moved = false;
  for (size_t k = d + 1; k < next; ++k) moved |= L[k].motion;
  if (L[d].motion && job.dialect == Dialect::Hpgl) moved = true;  // PD x,y moves as it lands
  if (moved) return next;
  size_t u = next;
  bool moves_ahead = false;
  while (u < L.size() && L[u].pen_down) moves_ahead |= L[u++].motion;
  if (u < L.size()) moves_ahead |= L[u].motion && job.dialect == Dialect::Hpgl;
  return moves_ahead ? d : std::min(u + 1, L.size());
}

// G-code: the job's own pen commands (with the dwell that follows them), the modal
// state at the resume point, and the travel there.
// `to` is where to travel (where line next - 1 ends, or a point on line next's path).
std::vector<std::string> gcode_preamble(const std::vector<JobLine>& L, size_t next, Point to) {
  GcodeModes modes;
  double feed = 0;  // in program units, as the job wrote it
  long pen_up = -1, pen_down = -1;
  for (size_t k = 0; k < L.size(); ++k) {
    if (is_gcode_pen_line(L[k].text)) {
      if (L[k].pen_down && (k < next || pen_down < 0)) pen_down = static_cast<long>(k);
      if (!L[k].pen_down && (k < next || pen_up < 0)) pen_up = static_cast<long>(k);
    }
    if (k >= next) continue;
    for (const GcodeWord& w : gcode_words(L[k].text)) {
      modes.apply(w);
      if (w.letter == 'F') feed = w.value;
    }
  }
  if (!modes.absolute)
    throw UserError("cannot resume: the job is in relative mode (G91) at line " + std::to_string(next + 1));
  std::vector<std::string> pre = {"G21", "G90"};
  auto with_dwell = [&](long k) {
    if (k < 0) return;
    pre.push_back(L[static_cast<size_t>(k)].text);
    if (static_cast<size_t>(k) + 1 < L.size() && is_dwell_line(L[static_cast<size_t>(k) + 1].text))
      pre.push_back(L[static_cast<size_t>(k) + 1].text);
  };
  if (pen_up < 0) throw UserError("cannot resume: the job never lifts the pen, so there is no pen-up command to use");
  with_dwell(pen_up);
  char buf[128];
  std::snprintf(buf, sizeof buf, "G0 X%.4f Y%.4f", to.x, to.y);
  pre.push_back(buf);
  if (pen_down_before(L, next)) with_dwell(pen_down);
  if (modes.scale != 1) pre.push_back("G20");
  // The motion mode and the feed, whichever mode is active: a controller that lost
  // power has F 0, and the job's next G1 may rely on an F set long before.
  if (feed > 0) {
    std::snprintf(buf, sizeof buf, "G%d F%.4g", modes.motion == 1 ? 1 : 0, feed);
    pre.push_back(buf);
  } else {
    pre.push_back(modes.motion == 1 ? "G1" : "G0");
  }
  return pre;
}

// HPGL: lift, the pen and velocity in use, travel, and the pen down again if it was.
std::vector<std::string> hpgl_preamble(const std::vector<JobLine>& L, size_t next, Point to) {
  std::string sp, vs;
  for (size_t k = 0; k < next; ++k) {
    if (L[k].text.rfind("SP", 0) == 0) sp = L[k].text;
    if (L[k].text.rfind("VS", 0) == 0) vs = L[k].text;
  }
  std::vector<std::string> pre = {"PU;"};
  if (!sp.empty()) pre.push_back(sp);
  if (!vs.empty()) pre.push_back(vs);
  char buf[128];
  std::snprintf(buf, sizeof buf, "PA;PU%.10g,%.10g;", to.x, to.y);
  pre.push_back(buf);
  if (pen_down_before(L, next)) pre.push_back("PD;");
  return pre;
}

}  // namespace

ResumePlan plan_resume(const Job& job, size_t next, const DevicePen& device) {
  const auto& L = job.lines;
  next = std::min(next, L.size());
  bool in_place = device.known && next > 0 && device.down == pen_down_before(L, next) &&
                  std::abs(device.x - L[next - 1].x) < 0.01 && std::abs(device.y - L[next - 1].y) < 0.01;
  if (in_place && job.dialect == Dialect::GCode) {
    // Pen already as it was: only the modal state needs restoring (as a full resume
    // from the settled point would restore it).
    ResumePlan rp{next, {}, {}, 0, {}};
    const size_t settled = settle_resume_point(job, next);
    for (const auto& l : gcode_preamble(L, settled, start_of(L, settled)))
      if (l == "G21" || l == "G90" || l == "G20" || l == "G0" || l == "G1" || l.rfind("G1 F", 0) == 0 ||
          l.rfind("G0 F", 0) == 0)
        rp.preamble.push_back(l);
    return rp;
  }
  next = settle_resume_point(job, next);
  const Point to = start_of(L, next);
  return {next, job.dialect == Dialect::GCode ? gcode_preamble(L, next, to) : hpgl_preamble(L, next, to), {}, 0, {}};
}

namespace {

// The device's pen is where and as the job leaves it just before line k.
bool device_before(const std::vector<JobLine>& L, size_t k, const DevicePen& d, double tol) {
  const double x = k ? L[k - 1].x : 0, y = k ? L[k - 1].y : 0;
  return pen_down_before(L, k) == d.down && std::abs(x - d.x) < tol && std::abs(y - d.y) < tol;
}

// The device's position lies on line k's move, short of its end (a move cut short by a
// hold or a reset: the pen is up by now whatever the move was).
bool device_within(const std::vector<JobLine>& L, size_t k, const DevicePen& d, double tol) {
  if (!L[k].motion || k == 0) return false;
  const double x0 = L[k - 1].x, y0 = L[k - 1].y, dx = L[k].x - x0, dy = L[k].y - y0, len2 = dx * dx + dy * dy;
  if (len2 <= 0) return false;
  const double u = std::clamp(((d.x - x0) * dx + (d.y - y0) * dy) / len2, 0.0, 1.0);
  // Begun means past its start: a pen standing at the start is device_before's to judge,
  // with the pen state (a pen lifted at the start of a stroke has not begun it).
  return u < 1 && u * std::sqrt(len2) > tol && std::hypot(x0 + u * dx - d.x, y0 + u * dy - d.y) < tol;
}

// The first line of the window from which the device's pen continues, or -1 if its pen
// matches nothing there (a board that came back fresh: its position is gone). `lo` is
// the window's first line. O(window).
long device_match(const Job& job, size_t next, const DevicePen& device, const ResumeWindow& window, size_t& lo,
                  size_t* last_match = nullptr) {
  const auto& L = job.lines;
  const double tol = job.dialect == Dialect::GCode ? 0.02 : 0.6;  // mm (a couple of steps); plotter units
  lo = next;
  for (size_t moves = 0; lo > 0 && moves < window.back_moves; --lo) moves += L[lo - 1].motion;
  size_t bytes = 0, end = lo;
  long first = -1;
  for (size_t k = lo; k <= L.size(); end = ++k) {
    if (device_before(L, k, device, tol) || (k < L.size() && device_within(L, k, device, tol))) {
      // The earliest match is taken; a later one (a path that passes the point again, as
      // a tree drawn back along its edges does) says how much may be drawn twice.
      if (first < 0) first = static_cast<long>(k);
      if (!last_match) break;
      *last_match = k;
    }
    if (k == L.size()) break;
    if (k >= next && (bytes += L[k].host_only ? 0 : L[k].text.size() + window.line_end_bytes) > window.ahead_bytes) break;
  }
  if (first >= 0) return first;
  // A board that restarted stands with its pen lifted at the end of a pen-down move: the
  // move ran, then the reset stopped the spindle (seen on the real firmware after a dead
  // host: without this the resume went back to the window's start and drew a stroke
  // twice). Only when nothing matched as it is; the earliest such move.
  if (window.back_moves > 0 && !device.down)
    for (size_t k = std::max<size_t>(lo, 1); k <= std::min(end, L.size()); ++k)
      if (L[k - 1].motion && pen_down_before(L, k) && std::abs(L[k - 1].x - device.x) < tol &&
          std::abs(L[k - 1].y - device.y) < tol)
        return static_cast<long>(k);
  return -1;
}

// The first line within window.unproven_bytes of the journal's end (`after` without
// any). O(window).
size_t unproven_start(const std::vector<JobLine>& L, size_t after, const ResumeWindow& window) {
  size_t lo = after;
  for (size_t bytes = 0; lo > 0 && bytes < window.unproven_bytes; --lo)
    bytes += L[lo - 1].host_only ? 0 : L[lo - 1].text.size() + window.line_end_bytes;
  return lo;
}

// Where to go on from the journal's last proof: its line, and the point on that line's
// path (projected onto it) if it lies inside a pen-down move, else the line's start.
// Empty `why` when the proof is usable; else why not. O(1).
struct ProofStart {
  size_t line = 0;
  bool split = false;
  Point at;
  std::string why;
};
ProofStart proof_start(const Job& job, const JournalState& journal) {
  const auto& L = job.lines;
  const ProvenPoint& p = journal.proven;
  ProofStart ps;
  if (p.line < 0) return {0, false, {}, "the journal holds no proof"};
  // The line under way is at most the first one not acknowledged (a sync line's answer
  // proves the next one's start).
  if (p.line > journal.last_acked + 1 || static_cast<size_t>(p.line) >= L.size())
    return {0, false, {}, "the last proof (line " + std::to_string(p.line + 1) + ") is past the acknowledged lines"};
  ps.line = static_cast<size_t>(p.line);
  const Point a = start_of(L, ps.line);
  const double dx = L[ps.line].x - a.x, dy = L[ps.line].y - a.y, len = std::hypot(dx, dy);
  const double u = len > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / (len * len), 0.0, 1.0) : 0.0;
  const bool gcode = job.dialect == Dialect::GCode;
  const double tol = gcode ? 0.02 : 0.6;  // mm (a couple of steps); plotter units
  const bool at_start = std::hypot(p.x - a.x, p.y - a.y) <= tol;
  // An HPGL instruction may be a polyline: only its start or end can be a proof.
  if (std::hypot(a.x + u * dx - p.x, a.y + u * dy - p.y) > tol ||
      (!gcode && !at_start && std::hypot(L[ps.line].x - p.x, L[ps.line].y - p.y) > tol))
    return {0, false, {}, "the last proof does not lie on line " + std::to_string(p.line + 1) + "'s path"};
  if (len > 0 && !at_start && std::hypot(L[ps.line].x - p.x, L[ps.line].y - p.y) <= (gcode ? 0.003 : tol)) {
    ++ps.line;  // at its end: the line is done
  } else if (gcode && len > 0 && u * len > tol && L[ps.line].motion && pen_down_before(L, ps.line)) {
    ps.split = true;
    ps.at = {a.x + u * dx, a.y + u * dy};
  }
  return ps;
}

// The pen-down length job lines [0, n) draw. O(job size).
double drawn_length(const Job& job, size_t n) {
  Job head;
  head.dialect = job.dialect;
  head.lines.assign(job.lines.begin(), job.lines.begin() + static_cast<long>(std::min(n, job.lines.size())));
  double len = 0;
  for (const Segment& s : job_segments(head)) len += std::hypot(s.x1 - s.x0, s.y1 - s.y0);
  return len;
}

// Pen-down path from `at` on line `from` (its start unless split) to the end of line
// `upto`: the most a resume from there draws again. O(job size).
double pen_down_length(const Job& job, size_t from, bool split, Point at, long upto) {
  if (upto < static_cast<long>(from)) return 0;
  double len = drawn_length(job, static_cast<size_t>(upto) + 1) - drawn_length(job, from);
  if (split) len -= std::hypot(at.x - start_of(job.lines, from).x, at.y - start_of(job.lines, from).y);
  return std::max(0.0, len);
}

}  // namespace

size_t resume_point(const Job& job, const JournalState& journal, const DevicePen& device, const ResumeWindow& window) {
  const size_t next = std::min(static_cast<size_t>(journal.last_acked + 1), job.lines.size());
  if (journal.stopped || !device.known || (window.ahead_bytes == 0 && window.back_moves == 0)) return next;
  size_t lo = next;
  const long k = device_match(job, next, device, window, lo);
  return k >= 0 ? static_cast<size_t>(k) : lo;
}

ResumePlan plan_resume_within(const Job& job, size_t line, double x, double y) {
  const auto& L = job.lines;
  if (line >= L.size() || !L[line].motion || !pen_down_before(L, line)) return plan_resume(job, line);
  const Point to{x, y};
  return {line, job.dialect == Dialect::GCode ? gcode_preamble(L, line, to) : hpgl_preamble(L, line, to), {}, 0, {}};
}

namespace {

// The device came back fresh (its pen matches nothing the journal allows): the last
// proof, when the journal has one that is consistent and not before the window's start;
// else the window's start, as before proofs were journalled. O(window).
ResumePlan resume_fresh(const Job& job, const JournalState& journal, size_t lo) {
  const ProofStart ps = proof_start(job, journal);
  const bool use = ps.why.empty() && ps.line >= lo;
  ResumePlan rp = use && ps.split ? plan_resume_within(job, ps.line, ps.at.x, ps.at.y) : plan_resume(job, use ? ps.line : lo);
  rp.redraw = pen_down_length(job, rp.next, use && ps.split, ps.at, journal.last_acked);
  if (use) {
    char b[160];
    std::snprintf(b, sizeof b, "from the last point proved drawn before the loss (at line %zu%s)", ps.line + 1,
                  ps.split ? ", split where a status report saw the pen" : "");
    rp.why = b;
  } else {
    rp.why = "from the first line the device may not have run (" +
             (ps.why.empty() ? "the last proof is earlier" : ps.why) + ")";
  }
  return rp;
}

}  // namespace

ResumePlan resume_from_journal(const Job& job, const JournalState& journal, const DevicePen& device,
                               const ResumeWindow& window) {
  const auto& L = job.lines;
  const size_t after = std::min(static_cast<size_t>(journal.last_acked + 1), L.size());
  size_t lo = after;
  const bool look = !journal.stopped && device.known && (window.ahead_bytes > 0 || window.back_moves > 0);
  // A paced HPGL plotter that does not say where its pen is may have lost its buffer.
  const bool unknown = !journal.stopped && !device.known && window.unproven_bytes > 0;
  // A board that lost its planner and stands at machine zero, pen up, was powered on
  // (or re-zeroed) there: that the job also passes there proves nothing (the job's
  // closing travel home would read as "it ran to the end").
  const bool zeroed = look && (window.back_moves > 0 || window.fresh_back_moves > 0) && !device.down &&
                      std::hypot(device.x, device.y) < 0.02;
  size_t last_match = 0;
  long match = look ? device_match(job, after, device, window, lo, &last_match) : static_cast<long>(after);
  if (zeroed || unknown) match = -1;
  if (match < 0) {
    // Fresh: every acknowledged move it could have held unrun may be undrawn.
    size_t fresh = after;
    for (size_t moves = 0; fresh > 0 && moves < window.fresh_back_moves; --fresh) moves += L[fresh - 1].motion;
    ResumePlan rp = resume_fresh(job, journal, std::min({lo, fresh, unproven_start(L, after, window)}));
    rp.note = std::string(unknown ? "the device cannot say where its pen is" : "the device's pen matches nothing the journal allows") +
              " (it may have come back fresh, its buffers lost): resuming at line " + std::to_string(rp.next + 1) + ", " + rp.why;
    return rp;
  }
  const size_t from = static_cast<size_t>(match);
  ResumePlan rp = plan_resume(job, from, device);
  // A stop that dropped the buffers rolled the line under way back: it may be redrawn.
  rp.redraw = pen_down_length(job, rp.next, false, {}, journal.stopped ? journal.last_acked + 1 : journal.last_acked);
  rp.why = journal.stopped ? "the device stopped with its buffers dropped: from the line it had under way"
           : look          ? "from where the device's pen stands"
                           : "from the line after the last the device acknowledged";
  if (from != after)
    rp.note = "the journal ends at line " + std::to_string(after) + " but the device's pen is where line " +
              std::to_string(from) + " left it" + (from > after ? " (it ran on after the host)" : "") +
              ": resuming from line " + std::to_string(from + 1);
  if (look && last_match > from && !zeroed) {
    // The pen stands where the path passes more than once: the earliest, so nothing is
    // lost; the path up to the last such place may be drawn again.
    rp.redraw = std::max(rp.redraw, pen_down_length(job, rp.next, false, {}, static_cast<long>(last_match) - 1));
    rp.note += std::string(rp.note.empty() ? "" : "; ") + "the job passes the pen's point again by line " +
               std::to_string(last_match) + ": resuming from the earlier (line " + std::to_string(from + 1) +
               "), up to that much may be drawn twice";
  }
  return rp;
}

}  // namespace stipplot::io
