// The G-code and HPGL writers, checked by reading their output back with small
// interpreters written here: every pen-down segment of the plan is drawn exactly once,
// nothing leaves the profile's travel, the pen state is right before every move, and
// units/feeds are set before the first move.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/device/carousel.hpp"
#include "drivers/device/machine.hpp"
#include "drivers/device/profile.hpp"
#include "util/error.hpp"
#include "writers/plan_fixtures.hpp"

using namespace stipplot;
namespace fs = std::filesystem;

namespace {
// Per process, so parallel test runs never share a file.
fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / ("stipplot-" + std::to_string(::getpid()) + "-" + name);
}
}  // namespace

namespace {

// A segment in device steps; a dot is a segment from a point to itself.
struct Seg {
  Steps a, b;
  bool operator<(const Seg& o) const {
    return std::tie(a.x, a.y, b.x, b.y) < std::tie(o.a.x, o.a.y, o.b.x, o.b.y);
  }
  bool operator==(const Seg& o) const { return a == o.a && b == o.b; }
};

// What the writers should draw: each stroke's segments after rounding, zero-length ones
// dropped; a stroke that rounds to a single point is a dot.
std::vector<Seg> expected_segments(const Plan& plan, const DeviceProfile& prof) {
  MachineTransform t(prof, plan.page);
  std::vector<Seg> out;
  for (const auto& l : plan.layers)
    for (const auto& s : l.strokes) {
      if (s.pts.empty()) continue;
      Steps pos = t.to_steps(s.pts[0]);
      bool drew = false;
      for (size_t i = 1; i < s.pts.size(); ++i) {
        Steps q = t.to_steps(s.pts[i]);
        if (q == pos) continue;
        out.push_back({pos, q});
        pos = q;
        drew = true;
      }
      if (!drew) out.push_back({pos, pos});
    }
  std::sort(out.begin(), out.end());
  return out;
}

// Coordinates must be whole multiples of the device's resolution.
int64_t to_steps(double mm, double step) {
  double s = mm / step;
  REQUIRE(std::fabs(s - std::round(s)) < 1e-6);
  return std::llround(s);
}

struct GcodeRun {
  std::vector<Seg> drawn;
  int pauses = 0;
  bool ended_pen_up = false;
};

// A minimal grbl: knows the pen commands of the profile, G0/G1/G4/M0/M2/M3/M4/M5, F, Z,
// and checks as it goes that the writer keeps the rules (millimetres and absolute before
// any move, no drawing with the pen up, no rapid with it down, moves inside the travel).
class GcodeChecker {
 public:
  explicit GcodeChecker(const DeviceProfile& prof) : prof_(prof), limits_(prof, Page{}) {}

  void line(const std::string& raw) {
    INFO("line: " << raw);
    read_words(raw);
    if (w_.count('F')) feed_set_ = true;
    for (const auto& c : codes_) {
      if (c == "G21") mm_ = true;
      if (c == "G90") absolute_ = true;
    }
    if (has("G0") || has("G1")) {
      REQUIRE(mm_);
      REQUIRE(absolute_);
    }
    pen();
    if (has("M0")) {
      REQUIRE_FALSE(down_);
      ++run_.pauses;
    }
    if (w_.count('X') || w_.count('Y')) move();
  }

  GcodeRun finish() {
    run_.ended_pen_up = !down_;
    std::sort(run_.drawn.begin(), run_.drawn.end());
    return run_;
  }

 private:
  void read_words(const std::string& raw) {
    std::string line = raw.substr(0, raw.find(';'));
    if (auto paren = line.find('('); paren != std::string::npos) line = line.substr(0, paren);
    std::istringstream in(line);
    w_.clear();
    codes_.clear();
    std::string word;
    while (in >> word) {
      char letter = word[0];
      REQUIRE(std::isupper(static_cast<unsigned char>(letter)));
      if (letter == 'G' || letter == 'M') codes_.push_back(word);
      else w_[letter] = std::stod(word.substr(1));
    }
  }
  bool has(const char* c) const { return std::find(codes_.begin(), codes_.end(), c) != codes_.end(); }

  // A pen-up after a pen-down that did not move is a touch (a dot).
  void lift() {
    if (down_ && !moved_since_down_) run_.drawn.push_back({pos_, pos_});
    down_ = false;
  }

  void pen() {
    const PenSetup& p = prof_.pen;
    if (p.method == PenMethod::servo) {
      if (has("M3")) {
        REQUIRE(w_.count('S'));
        bool now_down = w_['S'] == p.servo_down_s;
        if (now_down && !down_) moved_since_down_ = false;
        down_ = now_down;
      }
      if (has("M5")) lift();
    } else if (p.method == PenMethod::laser) {
      if (has("M4")) {
        REQUIRE(w_['S'] == p.laser_power_s);
        if (!down_) moved_since_down_ = false;
        down_ = true;
      }
      if (has("M5")) lift();
    } else if (p.method == PenMethod::z_axis && w_.count('Z')) {
      REQUIRE(!(w_.count('X') || w_.count('Y')));  // Z moves alone
      bool now_down = std::fabs(w_['Z'] - p.z_down_mm) < 1e-9;
      if (!now_down) {
        REQUIRE(std::fabs(w_['Z'] - p.z_up_mm) < 1e-9);
        REQUIRE(has("G0"));
        lift();
      } else {
        REQUIRE(has("G1"));
        REQUIRE(feed_set_);
        moved_since_down_ = false;
      }
      down_ = now_down;
    }
  }

  void move() {
    const double step = prof_.machine.resolution_mm;
    Steps q = pos_;
    if (w_.count('X')) q.x = to_steps(w_['X'], step);
    if (w_.count('Y')) q.y = to_steps(w_['Y'], step);
    REQUIRE(limits_.inside(q));
    if (has("G1")) {
      REQUIRE(down_);  // no drawing move with the pen up
      REQUIRE(feed_set_);
      run_.drawn.push_back({pos_, q});
      moved_since_down_ = true;
    } else {
      REQUIRE(has("G0"));
      REQUIRE_FALSE(down_);  // no rapid with the pen down
    }
    pos_ = q;
  }

  const DeviceProfile& prof_;
  MachineTransform limits_;
  GcodeRun run_;
  std::map<char, double> w_;
  std::vector<std::string> codes_;
  bool mm_ = false, absolute_ = false, feed_set_ = false, down_ = false, moved_since_down_ = false;
  Steps pos_{0, 0};
};

GcodeRun interpret_gcode(const std::vector<std::string>& lines, const DeviceProfile& prof) {
  GcodeChecker g(prof);
  for (const auto& l : lines) g.line(l);
  return g.finish();
}

struct HpglRun {
  std::vector<Seg> drawn;
  std::vector<int> pens;
  bool ended_pen_up = false;
  bool ended_sp0 = false;
};

HpglRun interpret_hpgl(const std::vector<std::string>& cmds, const DeviceProfile& prof) {
  HpglRun run;
  bool initialised = false, down = false;
  int pen = 0;
  Steps pos{0, 0};
  MachineTransform limits(prof, Page{});
  for (const auto& c : cmds) {
    INFO("command: " << c);
    REQUIRE(c.size() >= 3);
    REQUIRE(c.back() == ';');
    std::string op = c.substr(0, 2), args = c.substr(2, c.size() - 3);
    std::vector<long long> v;
    std::stringstream ss(args);
    std::string tok;
    while (std::getline(ss, tok, ',')) {
      if (op == "VS") break;
      REQUIRE(!tok.empty());
      v.push_back(std::stoll(tok));
    }
    if (op == "IN") {
      initialised = true;
      continue;
    }
    REQUIRE(initialised);
    if (op == "VS") {
      REQUIRE(prof.hpgl.velocity);
      REQUIRE(std::stod(args) <= prof.hpgl.max_velocity_cm_s);
    } else if (op == "SP") {
      REQUIRE(v.size() == 1);
      REQUIRE_FALSE(down);
      pen = static_cast<int>(v[0]);
      if (pen) run.pens.push_back(pen);
      run.ended_sp0 = pen == 0;
    } else if (op == "PU" || op == "PD") {
      REQUIRE(v.size() % 2 == 0);
      REQUIRE(v.size() / 2 <= static_cast<size_t>(prof.hpgl.max_points_per_command));
      if (op == "PD") {
        REQUIRE(pen > 0);  // a pen is in the holder
        if (v.empty()) run.drawn.push_back({pos, pos});
      }
      down = op == "PD";
      for (size_t i = 0; i < v.size(); i += 2) {
        Steps q{v[i], v[i + 1]};
        REQUIRE(limits.inside(q));
        if (down) run.drawn.push_back({pos, q});
        pos = q;
      }
    } else {
      FAIL("unexpected command " << c);
    }
  }
  run.ended_pen_up = !down;
  std::sort(run.drawn.begin(), run.drawn.end());
  return run;
}

}  // namespace

TEST_CASE("G-code for every grbl profile draws each planned segment exactly once, within travel", "[writers][gcode]") {
  for (const char* name : {"grbl-servo", "grbl-z", "grbl-laser"}) {
    INFO("profile " << name);
    DeviceProfile prof = find_profile(name);
    Plan plan = fixtures::random_plan(7, 3, 300, 60);
    auto lines = gcode_lines(plan, prof);
    GcodeRun run = interpret_gcode(lines, prof);
    auto want = expected_segments(plan, prof);
    REQUIRE(want.size() > 300 * 3);
    CHECK(run.drawn == want);
    CHECK(run.pauses == 2);  // one M0 per pen change
    CHECK(run.ended_pen_up);
  }
}

TEST_CASE("G-code header sets units, absolute mode and feed before the first move", "[writers][gcode]") {
  DeviceProfile prof = find_profile("grbl-servo");
  Plan plan = fixtures::random_plan(3, 1, 2, 2);
  auto lines = gcode_lines(plan, prof);
  size_t g21 = 0, g90 = 0, first_move = 0, first_g1 = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i] == "G21" && !g21) g21 = i + 1;
    if (lines[i] == "G90" && !g90) g90 = i + 1;
    if ((lines[i].rfind("G0 X", 0) == 0 || lines[i].rfind("G1 X", 0) == 0) && !first_move) first_move = i + 1;
    if (lines[i].rfind("G1 X", 0) == 0 && !first_g1) first_g1 = i + 1;
  }
  REQUIRE(g21);
  REQUIRE(g90);
  REQUIRE(first_move);
  CHECK(g21 < first_move);
  CHECK(g90 < first_move);
  // The first drawing move carries the profile's feed in mm/min.
  CHECK(lines[first_g1 - 1].find(" F3000") != std::string::npos);
  // Servo pen: M3 S1000 then the dwell from the profile.
  auto down = std::find(lines.begin(), lines.end(), "M3 S1000");
  REQUIRE(down != lines.end());
  CHECK(*(down + 1) == "G4 P0.15");
}

TEST_CASE("machine transform applies origin, axis signs and offsets", "[writers]") {
  Page a4;  // 210 x 297
  {
    DeviceProfile servo = find_profile("grbl-servo");  // bottom-left, y up
    MachineTransform t(servo, a4);
    Vec2 m = t.to_machine_mm({10, 20});
    CHECK(m.x == Approx(10));
    CHECK(m.y == Approx(277));
    CHECK(t.to_steps({10.004, 20}).x == 1000);
    CHECK(t.to_steps({10.006, 20}).x == 1001);
  }
  {
    DeviceProfile z = find_profile("grbl-z");  // top-left, y negative
    MachineTransform t(z, a4);
    Vec2 m = t.to_machine_mm({10, 20});
    CHECK(m.x == Approx(10));
    CHECK(m.y == Approx(-20));
  }
  {
    DeviceProfile hp = find_profile("hp7475a-a4");  // lower-left, 40 units/mm, hard-clip offset
    Page land{297, 210};
    MachineTransform t(hp, land);
    Steps s = t.to_steps({10.5, 210 - 8.49});  // the hard-clip corner
    CHECK(s.x == 0);
    CHECK(s.y == 0);
    CHECK(t.hi().x == 11040);
    CHECK(t.hi().y == 7721);
  }
}

TEST_CASE("a plan outside the travel is refused naming the point, and no file is left", "[writers]") {
  DeviceProfile prof = find_profile("grbl-servo");
  Plan plan = fixtures::random_plan(1, 1, 5, 0, 500, 297);
  plan.layers[0].strokes.push_back({{{100, 50}, {445.5, 60}}});
  const fs::path out = scratch("oob_test.gcode");
  fs::remove(out);
  try {
    write_gcode_file(plan, prof, out.string());
    FAIL("expected a UserError");
  } catch (const UserError& e) {
    std::string msg = e.what();
    CHECK(msg.find("445.50") != std::string::npos);
    CHECK(msg.find("grbl-servo") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(out));
  // a point off the page is refused even where the machine could reach it
  Plan off = fixtures::random_plan(1, 1, 5, 0);
  off.layers[0].strokes.push_back({{{-1, 50}}});
  try {
    gcode_lines(off, prof);
    FAIL("expected a UserError");
  } catch (const UserError& e) {
    CHECK(std::string(e.what()).find("(-1.00, 50.00) mm (layer 1) is off the 210.00 x 297.00 mm page") != std::string::npos);
  }
  // HPGL too: an A4 portrait page does not fit the 7475A's A4-landscape area.
  DeviceProfile hp = find_profile("hp7475a-a4");
  CHECK_THROWS_AS(hpgl_commands(fixtures::random_plan(2, 1, 50, 5), hp), UserError);
  // and the wrong protocol is refused
  CHECK_THROWS_AS(hpgl_commands(plan, prof), UserError);
  CHECK_THROWS_AS(gcode_lines(plan, hp), UserError);
}

TEST_CASE("HPGL for every HPGL profile draws each planned segment once with the right pens", "[writers][hpgl]") {
  for (const char* name : {"hp7475a-a4", "hp7475a-a3", "roland-dxy1300"}) {
    INFO("profile " << name);
    DeviceProfile prof = find_profile(name);
    // landscape pages that fit each device's area (the A4 one is 276 x 193 mm)
    bool small = std::string(name) == "hp7475a-a4";
    Plan plan = fixtures::random_plan(11, 4, 200, 40, small ? 297 : 420, small ? 210 : 297, 15);
    // one long stroke so chunking is exercised
    Stroke longs;
    for (int i = 0; i < 200; ++i) longs.pts.push_back({30 + i * 0.5, 50 + 10 * std::sin(i * 0.1)});
    plan.layers[1].strokes.push_back(longs);
    auto cmds = hpgl_commands(plan, prof);
    CHECK(cmds.front() == "IN;");
    HpglRun run = interpret_hpgl(cmds, prof);
    CHECK(run.drawn == expected_segments(plan, prof));
    CHECK(run.pens == std::vector<int>{1, 2, 3, 4});
    CHECK(run.ended_pen_up);
    CHECK(run.ended_sp0);
  }
}

TEST_CASE("HPGL y axis points up from the lower-left corner", "[writers][hpgl]") {
  DeviceProfile prof = find_profile("roland-dxy1300");
  Plan plan;
  plan.page = {420, 297};
  plan.layers.push_back({Pen{}, {{{{20, 20}, {30, 20}}}}});
  auto cmds = hpgl_commands(plan, prof);
  // (20, 20) from the top-left of an A3 sheet, with machine zero 8.03/10.5 mm in from the lower left
  CHECK(std::find(cmds.begin(), cmds.end(), "PU479,10660;") != cmds.end());
  CHECK(std::find(cmds.begin(), cmds.end(), "PD879,10660;") != cmds.end());
  CHECK(std::find(cmds.begin(), cmds.end(), "VS20;") != cmds.end());
}

TEST_CASE("HPGL plans a reload pause when the plan has more pens than the carousel", "[writers][hpgl]") {
  DeviceProfile prof = find_profile("hp7475a-a3");
  Plan plan = fixtures::random_plan(5, 8, 3, 0, 420, 297, 15);
  plan.layers[6].pen.name = "red";
  plan.layers[6].pen.color = {255, 0, 0};
  const auto cmds = hpgl_commands(plan, prof);
  std::vector<std::string> pauses, selects;
  for (const auto& c : cmds) {
    if (auto m = io::hpgl_pause_message(c)) pauses.push_back(*m);
    if (c.rfind("SP", 0) == 0) selects.push_back(c);
  }
  // pens 1-6 in their slots, then one stop to put pens 7 and 8 in (slots 1 and 2), the pen stowed first
  REQUIRE(pauses.size() == 1);
  CHECK(pauses[0] == "load pen 7 red #ff0000 in slot 1, pen 8 orange #000000 in slot 2");
  CHECK(selects == std::vector<std::string>{"SP1;", "SP2;", "SP3;", "SP4;", "SP5;", "SP6;", "SP0;", "SP1;", "SP2;", "SP0;"});
  // the job reader keeps the pause as one instruction the streamer can recognise
  std::string text;
  for (const auto& c : cmds) text += c;
  const io::Job job = io::parse_hpgl_job(text);
  size_t found = 0;
  for (const auto& l : job.lines) found += io::hpgl_pause_message(l.text).has_value();
  CHECK(found == 1);
  CHECK_FALSE(io::hpgl_pause_message("CO\"a plain comment\";"));
}

TEST_CASE("layers on one pen number share its slot, and pens beyond the carousel reload", "[writers][hpgl]") {
  PenSetup six;
  six.count = 6;
  Plan plan;
  plan.layers.resize(4);
  plan.layers[0].pen.number = 9;  // not in the carousel: a reload before the first layer
  plan.layers[1].pen.number = 2;
  plan.layers[2].pen.number = 12;
  plan.layers[3].pen.number = 3;
  const auto slots = plan_pen_slots(plan, six);
  REQUIRE(slots[0].reload.size() == 2);  // 9 and 12 go in at once, 2 and 3 stay
  CHECK(slots[0].reload[0].pen == 9);
  CHECK(slots[0].reload[1].pen == 12);
  CHECK(slots[1].slot == 2);
  CHECK(slots[2].reload.empty());
  CHECK(slots[3].slot == 3);
  CHECK(slots[0].slot != slots[2].slot);
}

TEST_CASE("writers write files atomically with the profile's line ending", "[writers]") {
  Plan plan = fixtures::random_plan(9, 2, 20, 5, 420, 297, 15);
  DeviceProfile hp = find_profile("hp7475a-a3");  // newline = false
  const fs::path h = scratch("writer_test.hpgl");
  write_hpgl_file(plan, hp, h.string());
  std::ifstream in(h);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(all.rfind("IN;", 0) == 0);
  CHECK(all.find('\n') == std::string::npos);
  std::string joined;
  for (const auto& c : hpgl_commands(plan, hp)) joined += c;
  CHECK(all == joined);
  fs::remove(h);

  const fs::path g = scratch("writer_test.gcode");
  DeviceProfile servo = find_profile("grbl-servo");
  write_gcode_file(plan, servo, g.string());
  std::ifstream gin(g);
  std::string line;
  size_t n = 0;
  while (std::getline(gin, line)) ++n;
  CHECK(n == gcode_lines(plan, servo).size());
  fs::remove(g);
}
