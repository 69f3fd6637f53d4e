#pragma once
// Compares what a simulator drew with what a job plans: equal as multisets.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "drivers/job/job.hpp"

namespace testjob {

struct Diff {
  size_t missing = 0, extra = 0, duplicated = 0;
  bool equal() const { return missing == 0 && extra == 0 && duplicated == 0; }
  std::string str() const {
    return "missing " + std::to_string(missing) + ", extra " + std::to_string(extra) + ", duplicated " +
           std::to_string(duplicated);
  }
};

inline Diff compare(const std::vector<stipplot::io::Segment>& planned, const std::vector<stipplot::io::Segment>& drawn,
                    double tol = 1e-6) {
  auto key = [tol](const stipplot::io::Segment& s) {
    auto q = [tol](double v) { return static_cast<long long>(std::llround(v / tol)); };
    return std::make_tuple(s.pen, q(s.x0), q(s.y0), q(s.x1), q(s.y1));
  };
  std::map<decltype(key(planned[0])), long> count;
  for (const auto& s : planned) ++count[key(s)];
  std::map<decltype(key(planned[0])), long> plan_count = count;
  Diff d;
  for (const auto& s : drawn) {
    auto k = key(s);
    if (!plan_count.count(k)) ++d.extra;
    else if (--count[k] < 0) ++d.duplicated;
  }
  for (const auto& [k, c] : count)
    if (c > 0) d.missing += static_cast<size_t>(c);
  return d;
}

// Drawn pieces that continue each other on one straight line (end of one = start of the
// next, same direction) joined: a pen lifted in a feed hold and lowered on resume at the
// same point draws one line in two pieces. For jobs with no two collinear segments in a row.
inline std::vector<stipplot::io::Segment> join_pieces(const std::vector<stipplot::io::Segment>& drawn, double tol = 1e-6) {
  std::vector<stipplot::io::Segment> out;
  for (const auto& s : drawn) {
    if (!out.empty()) {
      auto& p = out.back();
      const double ax = p.x1 - p.x0, ay = p.y1 - p.y0, bx = s.x1 - s.x0, by = s.y1 - s.y0;
      const bool joins = p.pen == s.pen && std::hypot(p.x1 - s.x0, p.y1 - s.y0) < tol;
      const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
      if (joins && la > 0 && lb > 0 && std::abs(ax * by - ay * bx) < 1e-9 * la * lb + tol * (la + lb) &&
          ax * bx + ay * by > 0) {
        p.x1 = s.x1;
        p.y1 = s.y1;
        continue;
      }
    }
    out.push_back(s);
  }
  return out;
}

// Whether `s` lies along one planned segment of the same pen (a piece of it, or a touch
// on it): what a plotter draws when a hold or a reset cuts a move short.
inline bool along_planned(const stipplot::io::Segment& s, const std::vector<stipplot::io::Segment>& planned,
                          double tol = 1e-3) {
  auto on = [tol](const stipplot::io::Segment& p, double x, double y) {
    const double dx = p.x1 - p.x0, dy = p.y1 - p.y0, len2 = dx * dx + dy * dy;
    const double t = len2 > 0 ? std::clamp(((x - p.x0) * dx + (y - p.y0) * dy) / len2, 0.0, 1.0) : 0.0;
    return std::hypot(p.x0 + t * dx - x, p.y0 + t * dy - y) < tol;
  };
  for (const auto& p : planned)
    if (p.pen == s.pen && on(p, s.x0, s.y0) && on(p, s.x1, s.y1)) return true;
  return false;
}

}  // namespace testjob
