// Motion/time model against hand-computed profiles.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "drivers/motion/time_model.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"

using namespace stipplot;
using namespace stipplot::motion;

TEST_CASE("a straight move is a hand-computed trapezoid", "[motion]") {
  MotionParams m;
  m.accel_mm_s2 = 1000;
  // 100 mm at 50 mm/s: 0.05 s and 1.25 mm to reach speed, the same to stop,
  // 97.5 mm cruising: 0.1 + 1.95 = 2.05 s.
  CHECK(polyline_seconds({{0, 0}, {100, 0}}, 50, m) == Approx(2.05).epsilon(1e-12));
  // Along y the same; diagonally each axis limits: a = 1000 * sqrt 2 along the move.
  CHECK(polyline_seconds({{0, 0}, {0, 100}}, 50, m) == Approx(2.05).epsilon(1e-12));
  const double a_diag = 1000 * std::sqrt(2.0);
  CHECK(polyline_seconds({{0, 0}, {100 / std::sqrt(2.0), 100 / std::sqrt(2.0)}}, 50, m) ==
        Approx(2 * 50 / a_diag + (100 - 50 * 50 / a_diag) / 50).epsilon(1e-9));
}

TEST_CASE("a move too short to reach speed is a triangle", "[motion]") {
  MotionParams m;
  m.accel_mm_s2 = 1000;
  // 1 mm: accelerate over 0.5 mm to v = sqrt(2 * 1000 * 0.5) = 31.6 mm/s < 50, then stop.
  const double vp = std::sqrt(1000.0);
  CHECK(polyline_seconds({{0, 0}, {1, 0}}, 50, m) == Approx(2 * vp / 1000).epsilon(1e-12));
  double peak = 0;
  CHECK(trapezoid_seconds(1, 0, 0, 50, 1000, &peak) == Approx(2 * vp / 1000));
  CHECK(peak == Approx(vp));
  // With entry and exit speeds: v0 = 10, v1 = 20, L = 1: vp^2 = (2000 + 100 + 400) / 2.
  const double vp2 = std::sqrt(1250.0);
  CHECK(trapezoid_seconds(1, 10, 20, 50, 1000) == Approx((vp2 - 10) / 1000 + (vp2 - 20) / 1000));
}

TEST_CASE("junction speed: straight on is unlimited, 90 degrees by grbl's formula", "[motion]") {
  MotionParams m;
  m.accel_mm_s2 = 1000;
  m.junction_deviation_mm = 0.01;
  CHECK(std::isinf(junction_speed_sqr({1, 0}, {1, 0}, m)));
  CHECK(junction_speed_sqr({1, 0}, {-1, 0}, m) == 0);
  // 90 degrees: sin(45) / (1 - sin 45) = 2.414; the junction direction (-1, 1)/sqrt 2
  // lets each axis give 1000, so a = 1414.2 along it.
  const double s = std::sqrt(0.5);
  const double expect = 1000 * std::sqrt(2.0) * 0.01 * s / (1 - s);
  CHECK(junction_speed_sqr({1, 0}, {0, 1}, m) == Approx(expect));
  CHECK(junction_speed_sqr({1, 0}, {0, 1}, m) < junction_speed_sqr({1, 0}, {s, s}, m));
  // A 90 degree corner costs time against the same length straight.
  const double corner = polyline_seconds({{0, 0}, {50, 0}, {50, 50}}, 50, m);
  const double straight = polyline_seconds({{0, 0}, {50, 0}, {100, 0}}, 50, m);
  CHECK(straight == Approx(polyline_seconds({{0, 0}, {100, 0}}, 50, m)));
  // Stop-and-go at the corner would add a full stop: the corner speed is in between.
  const double stop_go = 2 * polyline_seconds({{0, 0}, {50, 0}}, 50, m);
  CHECK(corner > straight);
  CHECK(corner < stop_go);
}

TEST_CASE("many short segments take longer than distance / speed", "[motion]") {
  MotionParams m;
  std::vector<Vec2> zigzag;
  for (int i = 0; i <= 400; ++i) zigzag.push_back({i * 0.5, (i % 2) * 0.5});
  double len = 0;
  for (size_t k = 1; k < zigzag.size(); ++k)
    len += std::hypot(zigzag[k].x - zigzag[k - 1].x, zigzag[k].y - zigzag[k - 1].y);
  const double t = polyline_seconds(zigzag, 50, m);
  CHECK(t > 1.5 * len / 50);
}

TEST_CASE("look-ahead: a short buffer must be able to stop, a long one cruises", "[motion]") {
  MotionParams m;
  m.accel_mm_s2 = 1000;
  std::vector<Vec2> line;
  for (int i = 0; i <= 100; ++i) line.push_back({i * 0.1, 0});  // 10 mm in 0.1 mm blocks
  const double single = polyline_seconds({{0, 0}, {10, 0}}, 50, m);
  m.lookahead_blocks = 15;  // 1.4 mm to stop from 50 mm/s needs 1.25: full speed
  CHECK(polyline_seconds(line, 50, m) == Approx(single).epsilon(1e-9));
  // Two blocks: each must leave room to stop within the next 0.1 mm, so it exits at
  // sqrt(2 * 1000 * 0.1) = 14.1 mm/s and peaks at sqrt((200 + 200 + 200) / 2) = 17.3 mm/s.
  m.lookahead_blocks = 2;
  const double slow = polyline_seconds(line, 50, m);
  const double per_block = 2 * (std::sqrt(300.0) - std::sqrt(200.0)) / 1000;
  CHECK(slow > 2 * single);
  CHECK(slow == Approx(100 * per_block).epsilon(0.03));
}

TEST_CASE("plan timeline: travel, pen events, per-layer sums", "[motion]") {
  Plan p;
  PlannedLayer a, b;
  a.strokes = {{{{10, 0}}}};
  b.strokes = {{{{10, 100}, {20, 100}}}};
  p.layers = {a, b};
  MotionParams m;
  const MotionTimeline tl = simulate_motion(p, m, {0, 0}, false, true);
  REQUIRE(tl.layer_seconds.size() == 2);
  const double travel_a = polyline_seconds({{0, 0}, {10, 0}}, m.speed_up_mm_s, m);
  CHECK(tl.layer_seconds[0] == Approx(travel_a + m.pen_drop_s + m.pen_lift_s));
  const double travel_b = polyline_seconds({{10, 0}, {10, 100}}, m.speed_up_mm_s, m);
  const double draw_b = polyline_seconds({{10, 100}, {20, 100}}, m.speed_down_mm_s, m);
  CHECK(tl.layer_seconds[1] == Approx(travel_b + m.pen_drop_s + draw_b + m.pen_lift_s));
  CHECK(tl.total_seconds == Approx(tl.layer_seconds[0] + tl.layer_seconds[1]));
  CHECK(estimate_seconds(p, m) == Approx(tl.total_seconds));
  // Blocks tile the time line.
  double t = 0;
  for (const auto& blk : tl.blocks) {
    CHECK(blk.start_s == Approx(t));
    t += blk.duration_s;
  }
  CHECK(t == Approx(tl.total_seconds));
  MotionParams bad;
  bad.accel_mm_s2 = -1;
  CHECK_THROWS_AS(estimate_seconds(p, bad), UserError);
}

TEST_CASE("a plan of long strokes is timed the same bit for bit on 1 and 3 threads", "[motion][threads]") {
  // Long strokes (timed side by side on several threads) among short ones and dots, in
  // two layers; the blocks' timeline (kept in order) as the reference.
  Plan p;
  p.layers.resize(2);
  uint64_t state = 99;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int s = 0; s < 60; ++s) {
    Stroke st;
    const int n = s % 7 == 0 ? 30000 : s % 3 == 0 ? 5000 : 1 + s % 40;
    double x = 20 + next() * 300, y = 20 + next() * 200, heading = next() * 6.28;
    for (int i = 0; i < n; ++i) {
      heading += (next() - 0.5) * 0.6;
      x = std::clamp(x + 0.3 * std::cos(heading), 0.0, 400.0);
      y = std::clamp(y + 0.3 * std::sin(heading), 0.0, 290.0);
      st.pts.push_back({x, y});
    }
    p.layers[static_cast<size_t>(s % 2)].strokes.push_back(st);
  }
  MotionParams m;
  set_thread_count(1);
  const MotionTimeline one = simulate_motion(p, m, {0, 0}, true);
  const MotionTimeline blocks = simulate_motion(p, m, {0, 0}, true, true);
  set_thread_count(3);
  const MotionTimeline three = simulate_motion(p, m, {0, 0}, true);
  set_thread_count(0);
  CHECK(one.total_seconds > 0);
  CHECK(std::memcmp(&one.total_seconds, &three.total_seconds, sizeof(double)) == 0);
  CHECK(std::memcmp(&one.total_seconds, &blocks.total_seconds, sizeof(double)) == 0);
  REQUIRE(three.layer_seconds.size() == 2);
  CHECK(std::memcmp(one.layer_seconds.data(), three.layer_seconds.data(), 2 * sizeof(double)) == 0);
}

TEST_CASE("one very long polyline is timed in pieces the same bit for bit as in one pass", "[motion][threads]") {
  // Wiggles (corners that cap the speed), long straight runs (where only the window's end
  // does, so a piece's two bounds meet late or never), repeated points and reversals; the
  // one-pass timing (the blocks kept, which never goes in pieces) is the reference.
  uint64_t state = 7;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  std::vector<Vec2> pts;
  double x = 100, y = 100, heading = 0;
  while (pts.size() < 200000) {
    const int kind = static_cast<int>(next() * 4);
    const int n = 1 + static_cast<int>(next() * 30000);
    for (int i = 0; i < n; ++i) {
      if (kind == 0) heading += (next() - 0.5) * 0.8;                // wiggle
      if (kind == 2 && i % 50 == 0) pts.push_back(pts.empty() ? Vec2{x, y} : pts.back());  // a repeated point
      if (kind == 3 && i % 997 == 0) heading += 3.14159265358979;     // a reversal
      const double step = kind == 1 ? 2.0 : 0.05 + next() * 0.3;      // kind 1: a straight run
      x = std::clamp(x + step * std::cos(heading), 0.0, 400.0);
      y = std::clamp(y + step * std::sin(heading), 0.0, 290.0);
      pts.push_back({x, y});
    }
  }
  MotionParams m;
  std::vector<MotionBlock> blocks;
  const double one_pass = polyline_seconds(pts, 40, m, &blocks);
  REQUIRE(blocks.size() > 100000);
  for (const int threads : {1, 2, 3}) {
    set_thread_count(threads);
    const double t = polyline_seconds(pts, 40, m);
    CAPTURE(threads);
    CHECK(std::memcmp(&t, &one_pass, sizeof(double)) == 0);
  }
  // The same ahead of the pieces' edges: a polyline that starts with repeated points.
  std::vector<Vec2> lead(20000, pts.front());
  lead.insert(lead.end(), pts.begin(), pts.begin() + 100000);
  blocks.clear();
  const double lead_one_pass = polyline_seconds(lead, 40, m, &blocks);
  set_thread_count(2);
  const double lead_pieces = polyline_seconds(lead, 40, m);
  set_thread_count(0);
  CHECK(std::memcmp(&lead_pieces, &lead_one_pass, sizeof(double)) == 0);
}
