// grbl's own settings against the profile's: what only changes the time is a warning,
// and the plot is timed again from the machine's numbers, as the machine really runs.
#include <catch2/catch.hpp>
#include <chrono>
#include <nlohmann/json.hpp>

#include "drivers/device/motion_setup.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/stream/grbl/machine_settings.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "sim/grbl_sim.hpp"
#include "test_util.hpp"

using namespace stipplot;

TEST_CASE("grbl settings that differ from the profile's are named and taken into the machine's timing", "[drivers][grbl]") {
  const motion::GrblSettings expected = grbl_settings_for(find_profile("grbl-servo"));
  std::map<int, double> same = {{100, expected.steps_per_mm[0]}, {110, expected.max_rate_mm_min[0]},
                                {120, expected.accel_mm_s2[0]}, {11, expected.junction_deviation_mm},
                                {1, expected.idle_lock_s * 1000}};
  CHECK_FALSE(io::grbl::compare_motion_settings(same, expected).changes_time());
  // grbl's factory settings: 500 mm/min and 10 mm/s^2, $1=25.
  std::map<int, double> factory = same;
  factory[110] = 500, factory[111] = 500, factory[120] = 10, factory[1] = 255;
  const auto c = io::grbl::compare_motion_settings(factory, expected);
  REQUIRE(c.changes_time());
  std::string all;
  for (const auto& t : c.time_changes) all += t + "; ";
  CHECK(all.find("$110=500 mm/min") != std::string::npos);
  CHECK(all.find("$120=10 mm/s^2") != std::string::npos);
  CHECK(all.find("$1=255 ms") != std::string::npos);
  CHECK(c.machine.max_rate_mm_min[1] == 500);
  CHECK(c.machine.accel_mm_s2[0] == 10);
  CHECK(c.machine.accel_mm_s2[2] == expected.accel_mm_s2[2]);  // not reported: the profile's
  CHECK(c.machine.idle_lock_s == 0);
}

TEST_CASE("plot times a job from grbl's own settings when they differ from the profile's", "[drivers][grbl][cli][timing][realtime]") {
  test::TempDir t;
  const std::string job = t.file("f.gcode");
  REQUIRE(test::run_cli("export " + std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg --profile grbl-servo -o " + job +
                        " -q").exit_code == 0);
  const DeviceProfile dev = find_profile("grbl-servo");
  sim::GrblSimConfig cfg = sim::grbl_sim_config(dev);
  cfg.machine.accel_mm_s2 = {60, 60, cfg.machine.accel_mm_s2[2]};  // a slower machine than the profile says
  cfg.speedup = 10;
  sim::GrblSim sim(cfg);
  const auto r = test::run_cli("plot " + job + " --port " + sim.open_pty() + " --profile grbl-servo --pen-change continue --json");
  INFO(r.err.substr(0, 1500));
  REQUIRE(r.exit_code == 0);
  const auto s = nlohmann::json::parse(r.out.substr(r.out.rfind("{\"")));
  REQUIRE(s.contains("settings_differ"));
  CHECK(s["settings_differ"].dump().find("$120=60") != std::string::npos);
  CHECK(r.err.find("grbl's settings differ from profile grbl-servo's") != std::string::npos);
  sim.wait_idle(10);
  const double ran = sim.stats().plot_time(), machine = s["estimate_s"], profile = s["estimate_s_profile"];
  INFO("the machine ran " << ran << " s; timed from its settings " << machine << " s, from the profile's " << profile << " s");
  CHECK(std::abs(machine / ran - 1) < 0.05);
  CHECK(std::abs(profile / ran - 1) > 0.10);  // the profile's numbers would have been wrong
}

TEST_CASE("an HPGL job sent to a grbl board is named as the wrong protocol within 10 s", "[drivers][hpgl][grbl]") {
  sim::GrblSimConfig cfg = sim::grbl_sim_config(find_profile("grbl-servo"));
  cfg.reset_on_open = true;  // an Arduino: opening the port reboots it, and it greets
  cfg.speedup = 10;
  sim::GrblSim sim(cfg);
  io::PosixSerial port(sim.open_pty(), {});
  io::hpgl::Streamer st(port, io::hpgl::options_for(find_profile("hp7475a-a4")));
  const auto t0 = std::chrono::steady_clock::now();
  std::string message;
  try {
    st.connect();
  } catch (const io::TransportError& e) {
    message = e.what();
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(message);
  CHECK(message.find("sounds like grbl") != std::string::npos);
  CHECK(secs < 10);
}
