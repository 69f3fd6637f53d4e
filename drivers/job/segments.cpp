#include "drivers/job/segments.hpp"

#include <cstdlib>
#include <sstream>
#include <string>

namespace stipplot::io {

void PenTrace::pen(bool d) {
  if (down_ && !d && !moved_) out_.push_back({x_, y_, x_, y_, pen_no_});
  if (d && !down_) moved_ = false;
  down_ = d;
}

void PenTrace::move(double nx, double ny) {
  if (down_ && (nx != x_ || ny != y_)) {
    out_.push_back({x_, y_, nx, ny, pen_no_});
    moved_ = true;
  }
  x_ = nx;
  y_ = ny;
}

namespace {

std::vector<Segment> gcode_segments(const Job& job) {
  PenTrace t;
  for (const auto& l : job.lines) {
    // G-code changes the pen in its own lines (M3/M5 or a Z move), so a line either
    // moves in XY with the pen as it was or changes the pen.
    if (l.motion) t.move(l.x, l.y);
    t.pen(l.pen_down);
  }
  t.pen(false);
  return t.segments();
}

// The numbers of an instruction in the reader's normal form ("PD10,20;"), which
// spells them with %.10g: split at ',' only, so "1e-05" stays one number.
std::vector<double> normal_form_numbers(const std::string& instruction) {
  std::vector<double> nums;
  std::string p = instruction.substr(2);
  if (!p.empty() && p.back() == ';') p.pop_back();
  std::stringstream ss(p);
  std::string tok;
  while (std::getline(ss, tok, ','))
    if (!tok.empty()) nums.push_back(std::strtod(tok.c_str(), nullptr));
  return nums;
}

// HPGL: replay each instruction (PU/PD x,y lists set the pen first, then move), since
// one instruction may pass through many points.
std::vector<Segment> hpgl_segments(const Job& job) {
  PenTrace t;
  bool absolute = true;
  for (const auto& l : job.lines) {
    const std::string& s = l.text;
    if (s.size() < 2 || s[0] == 0x1b) continue;
    const std::string mn = s.substr(0, 2);
    if (mn == "IN") {
      t.pen(false);
      t.move(0, 0);
      absolute = true;
      continue;
    }
    const std::vector<double> nums = normal_form_numbers(s);
    if (mn == "SP") {  // a pen change lifts the pen
      t.pen(false);
      t.set_pen_number(nums.empty() ? 0 : static_cast<int>(nums[0]));
      continue;
    }
    if (mn == "PU") t.pen(false);
    if (mn == "PD") t.pen(true);
    if (mn == "PA") absolute = true;
    if (mn == "PR") absolute = false;
    if (mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR")
      for (size_t k = 0; k + 1 < nums.size(); k += 2)
        t.move(absolute ? nums[k] : t.x() + nums[k], absolute ? nums[k + 1] : t.y() + nums[k + 1]);
  }
  t.pen(false);
  return t.segments();
}

// EBB: every line's pen state and position (an SP changes only the pen, an SM only the
// position).
std::vector<Segment> ebb_segments(const Job& job) {
  PenTrace t;
  for (const auto& l : job.lines) {
    if (l.host_only) continue;
    if (l.pen_down != t.down()) t.pen(l.pen_down);
    if (l.motion) t.move(l.x, l.y);
  }
  t.pen(false);
  return t.segments();
}

}  // namespace

std::vector<Segment> job_segments(const Job& job) {
  if (job.dialect == Dialect::Ebb) return ebb_segments(job);
  return job.dialect == Dialect::GCode ? gcode_segments(job) : hpgl_segments(job);
}

}  // namespace stipplot::io
