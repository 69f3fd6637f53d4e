#pragma once
// What a pen draws, from pen and move events: every pen-down move, and a touch where
// the pen went down and up again without moving. The same rules read a job
// (job_segments) and record what a simulated plotter did, so the two compare.
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

class PenTrace {
 public:
  void pen(bool down);
  void move(double x, double y);  // with the pen up only the position changes
  void set_pen_number(int n) { pen_no_ = n; }
  bool down() const { return down_; }
  double x() const { return x_; }
  double y() const { return y_; }
  const std::vector<Segment>& segments() const { return out_; }

 private:
  std::vector<Segment> out_;
  bool down_ = false, moved_ = false;
  double x_ = 0, y_ = 0;
  int pen_no_ = 1;
};

// The pen-down segments the job draws, in order. O(job size).
std::vector<Segment> job_segments(const Job& job);

}  // namespace stipplot::io
