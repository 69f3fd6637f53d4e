// Device profiles: every shipped one loads and is self-consistent; a broken profile is
// refused with the file and the key named.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivers/device/carousel.hpp"
#include "drivers/device/profile.hpp"
#include "util/error.hpp"

using namespace stipplot;
namespace fs = std::filesystem;

namespace {
std::string shipped_text(const std::string& name) {
  std::ifstream in(fs::path(STIPPLOT_SOURCE_DIR) / "drivers" / "profiles" / (name + ".toml"));
  REQUIRE(in);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string error_of(const std::string& text) {
  try {
    parse_profile(text, "test.toml");
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

std::string replace_line(std::string text, const std::string& starts_with, const std::string& with) {
  size_t pos = text.find("\n" + starts_with);
  REQUIRE(pos != std::string::npos);
  size_t end = text.find('\n', pos + 1);
  return text.replace(pos + 1, end - pos - 1, with);
}
}  // namespace

TEST_CASE("every shipped profile loads, and its name is its file name", "[profiles]") {
  auto all = list_profiles();
  std::vector<std::string> names;
  for (const auto& p : all) {
    names.push_back(p.name);
    CHECK(p.source.stem().string() == p.name);
    CHECK_FALSE(p.description.empty());
    CHECK(p.machine.travel_x_mm > 0);
    CHECK(p.motion.speed_up_mm_s >= p.motion.speed_down_mm_s);
  }
  for (const char* want : {"grbl-servo", "grbl-z", "grbl-laser", "hp7475a-a4", "hp7475a-a3", "roland-dxy1300"})
    CHECK(std::find(names.begin(), names.end(), want) != names.end());
  CHECK(find_profile(kDefaultProfile).name == kDefaultProfile);
}

TEST_CASE("shipped HPGL profiles carry the machines' plotter units and pens", "[profiles]") {
  DeviceProfile hp = find_profile("hp7475a-a4");
  CHECK(hp.protocol == Protocol::hpgl);
  CHECK(hp.machine.units_per_mm == 40);
  CHECK(hp.pen.count == 6);
  CHECK(hp.hpgl.max_velocity_cm_s == Approx(38.1));
  CHECK(std::llround(hp.machine.travel_x_mm * hp.machine.units_per_mm) == 11040);
  CHECK(std::llround(hp.machine.travel_y_mm * hp.machine.units_per_mm) == 7721);
  DeviceProfile dxy = find_profile("roland-dxy1300");
  CHECK(dxy.pen.count == 8);
  CHECK(dxy.machine.units_per_mm == 40);
  // eight pens fit the carousel, a ninth needs a reload
  Plan eight;
  eight.layers.resize(8);
  auto slots = plan_pen_slots(eight, dxy.pen);
  CHECK(slots[7].slot == 8);
  CHECK(slots[7].reload.empty());
  Plan nine;
  nine.layers.resize(9);
  slots = plan_pen_slots(nine, dxy.pen);
  CHECK(slots[8].pen == 9);
  CHECK(slots[8].reload.size() == 1);
  DeviceProfile servo = find_profile("grbl-servo");
  CHECK(servo.pen.count == 1);  // one holder: M0 pauses instead
  CHECK(servo.serial.rx_buffer_bytes == 128);
}

TEST_CASE("motion parameters come from the profile", "[profiles]") {
  DeviceProfile z = find_profile("grbl-z");
  const MotionParams& m = z.motion;
  CHECK(m.speed_down_mm_s == 40);
  CHECK(m.speed_up_mm_s == 100);
  CHECK(m.accel_mm_s2 == 500);
  CHECK(m.junction_deviation_mm == 0.01);
  CHECK(m.pen_lift_s == 0.2);
  CHECK(m.lookahead_blocks == 15);
}

TEST_CASE("a missing key is named with its section and the file", "[profiles]") {
  std::string text = shipped_text("grbl-servo");
  REQUIRE(error_of(text).empty());
  std::string e = error_of(replace_line(text, "speed_down_mm_s", ""));
  CHECK(e.find("test.toml") != std::string::npos);
  CHECK(e.find("motion.speed_down_mm_s is missing") != std::string::npos);
  e = error_of(replace_line(shipped_text("hp7475a-a4"), "max_points_per_command", ""));
  CHECK(e.find("hpgl.max_points_per_command is missing") != std::string::npos);
  e = error_of(replace_line(text, "servo_down_s", ""));
  CHECK(e.find("pen.servo_down_s is missing") != std::string::npos);
  e = error_of(replace_line(text, "name = ", ""));
  CHECK(e.find("key name is missing") != std::string::npos);
}

TEST_CASE("a wrong-typed, out-of-range or unknown key is named", "[profiles]") {
  std::string text = shipped_text("grbl-servo");
  std::string e = error_of(replace_line(text, "accel_mm_s2", "accel_mm_s2 = \"fast\""));
  CHECK(e.find("motion.accel_mm_s2 must be a number") != std::string::npos);
  e = error_of(replace_line(text, "baud", "baud = 9600.5"));
  CHECK(e.find("serial.baud must be an integer") != std::string::npos);
  e = error_of(replace_line(text, "speed_up_mm_s", "speed_up_mm_s = -5"));
  CHECK(e.find("motion.speed_up_mm_s must be between") != std::string::npos);
  e = error_of(replace_line(text, "origin =", "origin = \"middle\""));
  CHECK(e.find("machine.origin must be one of top-left|bottom-left") != std::string::npos);
  e = error_of(replace_line(text, "method", "method = \"z\""));
  CHECK(e.find("pen.z_up_mm is missing") != std::string::npos);
  e = error_of(replace_line(text, "dot_dwell_s", "dot_dwell_s = 0\nz_up_mm = 3"));
  CHECK(e.find("unknown key pen.z_up_mm") != std::string::npos);
  e = error_of(replace_line(text, "newline", "newline = \"yes\""));
  CHECK(e.find("serial.newline must be true or false") != std::string::npos);
  e = error_of(text + "\n[extra]\nx = 1\n");
  CHECK(e.find("unknown key extra") != std::string::npos);
  e = error_of("name = \"x\"\nthis is not toml");
  CHECK(e.find("test.toml line 2") != std::string::npos);
}

TEST_CASE("the profile option takes a path, and an unknown name lists the known ones", "[profiles]") {
  fs::path p = fs::path(STIPPLOT_SOURCE_DIR) / "drivers" / "profiles" / "grbl-laser.toml";
  CHECK(find_profile(p.string()).pen.method == PenMethod::laser);
  try {
    find_profile("no-such-plotter");
    FAIL("expected a UserError");
  } catch (const UserError& e) {
    std::string m = e.what();
    CHECK(m.find("no-such-plotter") != std::string::npos);
    CHECK(m.find("hp7475a-a4") != std::string::npos);
  }
  CHECK_THROWS_AS(find_profile("/nonexistent/dir/x.toml"), UserError);
}
