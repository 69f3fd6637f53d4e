#pragma once
// Small job generators for the driver tests: G-code for a servo-pen grbl plotter and
// HPGL, from strokes (one point = a dot), deterministic for a seed.
#include <cstdio>
#include <string>
#include <vector>

#include "util/rng.hpp"

namespace testjob {

struct Pt {
  double x, y;
};
using Strokes = std::vector<std::vector<Pt>>;

inline Strokes random_strokes(uint64_t seed, int n, int max_pts, double size = 100) {
  stipplot::Rng rng(seed);
  Strokes s;
  for (int i = 0; i < n; ++i) {
    int k = 1 + static_cast<int>(rng.uniform() * max_pts);
    std::vector<Pt> st;
    double x = 5 + rng.uniform() * (size - 10), y = 5 + rng.uniform() * (size - 10);
    for (int j = 0; j < k; ++j) {
      st.push_back({x, y});
      x = std::min(size - 1, std::max(1.0, x + (rng.uniform() - 0.5) * 4));
      y = std::min(size - 1, std::max(1.0, y + (rng.uniform() - 0.5) * 4));
    }
    s.push_back(st);
  }
  return s;
}

inline std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

// Servo pen: M3 S30 down, M5 up, with a short dwell after each.
inline std::string gcode(const Strokes& strokes, double feed = 3000, bool z_pen = false) {
  std::string g = "G21\nG90\n";
  g += z_pen ? "G0 Z2\n" : "M5\n";
  for (const auto& s : strokes) {
    g += "G0 X" + fmt(s[0].x) + " Y" + fmt(s[0].y) + "\n";
    g += z_pen ? "G1 Z-1 F600\n" : "M3 S30\nG4 P0.05\n";
    for (size_t i = 1; i < s.size(); ++i) g += "G1 X" + fmt(s[i].x) + " Y" + fmt(s[i].y) + " F" + fmt(feed) + "\n";
    g += z_pen ? "G0 Z2\n" : "M5\nG4 P0.05\n";
  }
  g += "G0 X0 Y0\n";
  return g;
}

inline std::string hpgl(const Strokes& strokes, double upm = 40) {
  std::string h = "IN;SP1;";
  auto pu = [&](double v) { return std::to_string(static_cast<long>(v * upm + 0.5)); };
  for (const auto& s : strokes) {
    h += "PU" + pu(s[0].x) + "," + pu(s[0].y) + ";PD";
    for (size_t i = 1; i < s.size(); ++i) {
      if (i > 1) h += ',';
      h += pu(s[i].x);
      h += ',';
      h += pu(s[i].y);
    }
    h += ";PU;";
  }
  h += "SP0;";
  return h;
}

}  // namespace testjob
