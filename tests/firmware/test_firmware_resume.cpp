// Resume on the real grbl 1.1h firmware: the link to the board drops a quarter, half and
// three quarters into a tree job (the board on its own power runs on with what it holds),
// then `stipplot plot --resume` on a new connection finishes the job. The firmware's block
// log is the judge: every mark of the job drawn, at most the interrupted one twice, or,
// where the pen stands at a point the tree's trail passes again (drawn back along an
// edge), no more pen-down path drawn twice than the resume said it might.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "firmware/plot_jobs.hpp"

using namespace firmware;

TEST_CASE("stipplot plot on the grbl firmware: a dropped link at 25, 50 and 75 %, then --resume: nothing lost, at most one mark or what the resume announced doubled",
          "[firmware]") {
  test::TempDir t;
  const std::string profile = "grbl-servo";
  const jobs::Job job = jobs::tree_job(profile, t.file("tree.gcode"), "--page 25x20mm --margin 2 -a 7.5 -b 12");
  const std::string gcode = test::read_file(job.path);
  const size_t n = jobs::job_lines(gcode).size();
  auto job_line = [](const std::string& l) { return !l.empty() && l[0] != '$'; };
  for (const double at : {0.25, 0.5, 0.75}) {
    const std::string path = t.file("cut.gcode");
    std::ofstream(path) << gcode;
    std::remove((path + ".journal").c_str());
    GrblFirmware fw(profile + "-bf");
    const size_t cut_line = static_cast<size_t>(at * static_cast<double>(n));
    fw.cut_after_client_lines(cut_line, Cut::DropLink, job_line);
    const jobs::Plot first = jobs::plot(path, profile, fw.port());
    REQUIRE(fw.cut_done());
    CHECK(first.run.exit_code != 0);
    REQUIRE(fw.wait_idle(120));  // the board finishes what it had
    const jobs::Plot second = jobs::plot(path, profile, fw.reconnect(), "", true);
    INFO("cut after line " << cut_line << " of " << n << ": " << first.run.err << second.run.err);
    REQUIRE(second.completed());
    REQUIRE(fw.wait_idle(60));
    const FirmwareRecord rec = fw.record();
    const JobCheck jc = check_job(gcode, rec, PenRule::for_profile(profile));
    std::printf("firmware drop-link at %2.0f %% (line %zu of %zu) | %s\n", 100 * at, cut_line, n, jc.marks.summary().c_str());
    for (const Mark& m : jc.marks.doubled_marks) std::printf("  doubled %s\n", describe(m, rec.settings).c_str());
    std::printf("  first: %s\n  resume: %s\n", first.run.err.c_str(), second.summary.dump().c_str());
    std::fflush(stdout);
    INFO(explain(jc, rec.settings));
    CHECK(jc.marks.expected_segments + jc.marks.expected_dots > 0);
    CHECK(jc.marks.lost == 0);
    double doubled_mm = 0;
    for (const Mark& m : jc.marks.doubled_marks)
      doubled_mm += std::hypot((m.b.x - m.a.x) / rec.settings.steps_per_mm[0], (m.b.y - m.a.y) / rec.settings.steps_per_mm[1]);
    const double announced_mm = second.summary.value("resume", nlohmann::json::object()).value("redraw_mm", 0.0);
    std::printf("  drawn twice %.2f mm, the resume announced up to %.2f mm\n", doubled_mm, announced_mm);
    CHECK((jc.marks.doubled <= 1 || doubled_mm <= announced_mm + 0.05));
    CHECK(jc.marks.extra == 0);
  }
}
