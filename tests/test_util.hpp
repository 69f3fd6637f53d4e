#pragma once
// Small helpers shared by the tests: temp dirs, running the CLI, synthetic images.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"

namespace test {

namespace fs = std::filesystem;

// A fresh directory under the system temp dir, removed on destruction.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("stipplot-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};

// Runs the stipplot CLI with `args` (already shell-quoted where needed).
inline RunResult run_cli(const std::string& args) {
  TempDir t;
  std::string cmd = std::string(STIPPLOT_BIN) + " " + args + " >" + t.file("out") + " 2>" + t.file("err") + " </dev/null";
  int rc = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
  auto slurp = [](const std::string& p) {
    std::ifstream f(p);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  r.out = slurp(t.file("out"));
  r.err = slurp(t.file("err"));
  return r;
}

// Runs the CLI with stdout and stderr merged; `status` is pclose's raw status.
inline std::string run_cli_merged(const std::string& args, int& status) {
  std::string cmd = std::string(STIPPLOT_BIN) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run " + cmd);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  status = pclose(p);
  return out;
}

// A file of the project's examples/ folder.
inline std::string example(const std::string& name) { return std::string(STIPPLOT_SOURCE_DIR) + "/examples/" + name; }

inline int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

inline std::string read_file(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// True when `edges` (anything with .a and .b) are n - 1 edges joining n points without a
// cycle: a spanning tree.
template <class Edge>
bool spans(const std::vector<Edge>& edges, size_t n) {
  if (n == 0) return edges.empty();
  if (edges.size() != n - 1) return false;
  std::vector<uint32_t> parent(n);
  for (uint32_t i = 0; i < n; ++i) parent[i] = i;
  auto find = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Edge& e : edges) {
    const uint32_t a = find(e.a), b = find(e.b);
    if (a == b) return false;
    parent[a] = b;
  }
  return true;
}

// Fig. 2-like: a dark spiral of several turns with thin straight lines from it, on
// white, anti-aliased as a scanned drawing is (coverage-weighted grey at the edges).
inline stipplot::Image spiral_image(int size = 256, double line_level = 0) {
  std::vector<uint8_t> g(static_cast<size_t>(size) * size, 255);
  const double cx = size / 2.0, cy = size / 2.0;
  const double k = size / 40.0;  // r = k * theta: a turn every 2 pi k px
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double ink = 0;
      // 4x4 supersampling for the coverage
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          double dx = x + (sx + 0.5) / 4 - cx, dy = y + (sy + 0.5) / 4 - cy;
          double rad = std::sqrt(dx * dx + dy * dy), th = std::atan2(dy, dx);
          double t = (rad / k - th) / (2 * M_PI);
          double dist = std::abs(t - std::round(t)) * 2 * M_PI * k;
          bool on = dist < 1.5 && rad < size * 0.45;
          for (int i = 0; i < 8 && !on; ++i) {
            double a = i * M_PI / 4 + 0.2;
            double along = dx * std::cos(a) + dy * std::sin(a), across = -dx * std::sin(a) + dy * std::cos(a);
            if (along > size * 0.2 && std::abs(across) < 0.5) on = true;
          }
          ink += on ? 1.0 / 16 : 0;
        }
      g[static_cast<size_t>(y) * size + x] = static_cast<uint8_t>(std::lround(255 - ink * (255 - line_level)));
    }
  return stipplot::Image::from_grey(size, size, g);
}

// Fig. 9-like: a mid-grey ground with both white and black lines.
inline stipplot::Image grey_lines_image(int w = 256, int h = 256) {
  std::vector<uint8_t> g(static_cast<size_t>(w) * h, 128);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t& v = g[static_cast<size_t>(y) * w + x];
      if ((x / 4) % 8 == 1) v = 255;          // white vertical bands, 4 px wide
      if ((y / 4) % 8 == 5) v = 0;            // black horizontal bands
      if (std::abs((x - y) % 48) < 3) v = 230; // light diagonal lines
    }
  return stipplot::Image::from_grey(w, h, g);
}

// Each line of `d` cut into pieces of at most 0.05 mm: f(layer, x of the piece's middle,
// its length), so ink can be counted where it lies along x.
template <class F>
void for_each_line_piece(const stipplot::Drawing& d, F f) {
  for (const stipplot::Layer& l : d.layers)
    for (const stipplot::Polyline& pl : l.lines)
      for (size_t i = 1; i < pl.pts.size(); ++i) {
        const stipplot::Vec2 a = pl.pts[i - 1], b = pl.pts[i];
        const double seg = std::hypot(b.x - a.x, b.y - a.y);
        const int pieces = std::max(1, static_cast<int>(std::ceil(seg / 0.05)));
        for (int k = 0; k < pieces; ++k) f(l, a.x + (b.x - a.x) * (k + 0.5) / pieces, seg / pieces);
      }
}

}  // namespace test
