// Resuming on a reset EBB (drivers/stream/ebb/reset.hpp): the SM split, the proof search
// and the plan, without a board. (The firmware tests are in test_ebb_firmware.cpp.)
#include <catch2/catch.hpp>

#include <random>

#include "drivers/device/profile.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/stream/ebb/reset.hpp"

using namespace stipplot;
using stipplot::io::ebb::Steps;

namespace {

// Motor steps of a machine position (mm) at 80 steps/mm.
Steps st(double x, double y) { return io::ebb_motor_steps(x, y, 80); }

// A: (0,0) -> (10,0) pen up; B: (10,0) -> (10,10) pen down; C: (10,10) -> (0,-10), crossing
// A at (5,0). Lines: 0 EM, 1 SP up, 2 A, 3 SP down, 4 B, 5 C, 6 SP up.
const char* kCrossing = "EM,1,1\nSP,1,130\nSM,100,800,800\nSP,0,146\nSM,100,800,-800\nSM,200,-2400,800\nSP,1,130\n";

}  // namespace

TEST_CASE("EBB reset: an SM split at a proven point keeps every step and a proportional duration", "[ebb]") {
  const auto r = io::ebb::sm_remainder(25, 100, -40, {37, -15});
  CHECK(r.s1 == 63);
  CHECK(r.s2 == -25);
  CHECK(r.ms == 16);  // 25 ms * 63 / 100, rounded
  // Never faster than 25 steps per ms, never under 1 ms.
  CHECK(io::ebb::sm_remainder(4, 100, 0, {1, 0}).ms == 4);
  CHECK(io::ebb::sm_remainder(1, 25, 0, {24, 0}).ms == 1);
  CHECK(io::ebb::sm_remainder(25, 600, 10, {0, 0}).ms == 25);
  // No drift: the part done and the rest are the SM's own steps, whatever the split.
  std::mt19937 rng(7);
  for (int k = 0; k < 2000; ++k) {
    const int64_t ms = std::uniform_int_distribution<int64_t>(1, 25)(rng);
    const int64_t s1 = std::uniform_int_distribution<int64_t>(-25 * ms, 25 * ms)(rng);
    const int64_t s2 = std::uniform_int_distribution<int64_t>(-25 * ms, 25 * ms)(rng);
    const double t = std::uniform_real_distribution<double>(0, 1)(rng);
    const Steps done{std::llround(t * static_cast<double>(s1)), std::llround(t * static_cast<double>(s2))};
    const auto rest = io::ebb::sm_remainder(ms, s1, s2, done);
    REQUIRE(done[0] + rest.s1 == s1);
    REQUIRE(done[1] + rest.s2 == s2);
    REQUIRE(rest.ms >= 1);
    REQUIRE(rest.ms <= ms);
    REQUIRE(std::llabs(rest.s1) <= 25 * rest.ms);
    REQUIRE(std::llabs(rest.s2) <= 25 * rest.ms);
  }
}

TEST_CASE("EBB reset: a QS position is matched to the move it lies on, the earlier at a crossing", "[ebb]") {
  const io::Job job = io::parse_ebb_job(kCrossing, 80);
  REQUIRE(job.lines.size() == 7);
  CHECK(io::ebb::first_on_path(job, 0, 6, st(5, 0), 80) == 2);   // A and C cross there: A
  CHECK(io::ebb::first_on_path(job, 3, 6, st(5, 0), 80) == 5);   // past A: C
  CHECK(io::ebb::first_on_path(job, 0, 6, st(10, 0), 80) == 2);  // A's end is B's start: A
  CHECK(io::ebb::first_on_path(job, 0, 6, st(10, 5), 80) == 4);  // B
  CHECK(io::ebb::first_on_path(job, 0, 6, st(2.5, -5), 80) == 5);  // C only
  CHECK(io::ebb::first_on_path(job, 0, 6, st(5, 3), 80) == -1);  // on no move
  CHECK(io::ebb::first_on_path(job, 0, 4, st(2.5, -5), 80) == -1);  // C is past the window
  // A motor a step behind the other is still on the move.
  const Steps s = st(5, 0);
  CHECK(io::ebb::first_on_path(job, 0, 6, {s[0] + 1, s[1]}, 80) == 2);
  CHECK(io::ebb::first_on_path(job, 0, 6, {s[0] + 4, s[1] - 4}, 80) == -1);  // 0.05 mm off both
  // Lines that do not move hold nothing, even where the carriage stands.
  CHECK_FALSE(io::ebb::on_sm_path(job, 3, st(10, 0), 80));
}

TEST_CASE("EBB reset: the commands a lost FIFO may have held", "[ebb]") {
  const io::Job job = io::parse_ebb_job(kCrossing, 80);
  CHECK(io::ebb::first_unsure(job, 6, 2) == 4);  // SP, C, B: the FIFO's 2 and the one running
  CHECK(io::ebb::first_unsure(job, 6, 32) == 0);
  CHECK(io::ebb::first_unsure(job, -1, 2) == 0);
}

TEST_CASE("EBB reset: the resume plan splits the proven move and travels there from home", "[ebb]") {
  const io::Job job = io::parse_ebb_job(kCrossing, 80);
  const DeviceProfile prof = find_profile("axidraw-v3");
  io::JournalState j;
  j.last_acked = 6;
  // Each SM of the travel, summed: where it ends.
  auto travel_end = [](const std::vector<std::string>& pre) {
    Steps at{0, 0};
    for (const std::string& l : pre)
      if (l.rfind("SM,", 0) == 0) {
        const io::EbbCommand c = io::parse_ebb_command(l, 0);
        REQUIRE(c.ms >= 1);
        REQUIRE(std::llabs(c.s1) <= 25 * c.ms);
        REQUIRE(std::llabs(c.s2) <= 25 * c.ms);
        at[0] += c.s1, at[1] += c.s2;
      }
    return at;
  };
  SECTION("a proof inside C, a pen-down move: C split there") {
    const Steps q = st(5, 0);
    j.proven = {5, 5, 0, 0};
    const io::ResumePlan rp = io::ebb::plan_reset_resume(job, j, prof, 2);
    CHECK(rp.next == 6);
    REQUIRE(rp.preamble.size() >= 6);
    CHECK(rp.preamble[0] == "EM,1,1");
    CHECK(rp.preamble[1] == "SP,1,130");
    // The accelerated travel: more than one SM, ending at the proven point to the step.
    CHECK(rp.preamble.size() > 6);
    CHECK(rp.preamble[rp.preamble.size() - 2] == "SP,0,146");
    // C's rest: C's steps less the part done (C starts at (10,10)).
    const Steps c0 = st(10, 10);
    const Steps done{q[0] - c0[0], q[1] - c0[1]};
    CHECK(rp.preamble.back() == "SM,100," + std::to_string(-2400 - done[0]) + "," + std::to_string(800 - done[1]));
    std::vector<std::string> travel(rp.preamble.begin(), rp.preamble.end() - 2);
    CHECK(travel_end(travel) == q);
    CHECK(travel_end(rp.preamble) == st(0, -10));  // and C's end after its rest
    CHECK(rp.redraw == Approx(std::hypot(5.0, 10.0)).epsilon(0.001));
    CHECK(rp.why.find("proved") != std::string::npos);
  }
  SECTION("no proof: from the first line the FIFO may have held, the pen put down again") {
    const io::ResumePlan rp = io::ebb::plan_reset_resume(job, j, prof, 2);
    CHECK(rp.next == 4);
    CHECK(rp.preamble.back() == "SP,0,146");
    CHECK(travel_end(rp.preamble) == st(10, 0));
    CHECK(rp.why.find("may not have run") != std::string::npos);
  }
  SECTION("a proof before the FIFO's bound is not used") {
    j.proven = {2, 5, 0, 0};
    CHECK(io::ebb::plan_reset_resume(job, j, prof, 2).next == 4);
  }
  SECTION("a proof that lies on no move of its line is not used") {
    j.proven = {5, 5, 3, 0};
    const io::ResumePlan rp = io::ebb::plan_reset_resume(job, j, prof, 2);
    CHECK(rp.next == 4);
    CHECK(rp.why.find("does not lie on line 6") != std::string::npos);
  }
  SECTION("a proof at a pause counted as done: from the line after it, nothing drawn again") {
    const io::Job paused = io::parse_ebb_job(
        "EM,1,1\nSP,1,130\nSM,100,800,800\nSP,0,146\nSM,100,800,-800\nSP,1,130\n# pause: Change pen: pen 2\n"
        "SP,0,146\nSM,100,800,800\nSP,1,130\n",
        80);
    j.last_acked = 6;       // the pause, counted as done
    j.proven = {4, 10, 10, 0};  // where the board stood at it: the end of line 5
    const io::ResumePlan rp = io::ebb::plan_reset_resume(paused, j, prof, 32);
    CHECK(rp.next == 7);
    CHECK(travel_end(rp.preamble) == st(10, 10));
    CHECK(rp.preamble.back().rfind("SM,", 0) == 0);  // no pen-down: the pen was up there
    CHECK(rp.redraw == 0);
  }
  SECTION("a FIFO reaching back before the first move: the job from its start") {
    const io::ResumePlan rp = io::ebb::plan_reset_resume(job, j, prof, 32);
    CHECK(rp.next == 0);
    CHECK(rp.preamble.empty());
  }
}
