// The plot's progress is drawn over the method's preview: the trace must put each job
// line's mark back where the drawing had it on the method's page, through the device's
// coordinates (G-code mm, HPGL plotter units, y up or down) and the layout's turn.
#include <catch2/catch.hpp>

#include "drivers/device/machine.hpp"
#include "drivers/device/profile.hpp"
#include "serve/plot_trace.hpp"

using namespace stipplot;

TEST_CASE("the plot trace puts each mark back on the method's page, through the device and the layout", "[serve]") {
  for (const char* name : {"grbl-servo", "grbl-z", "hp7475a-a4", "roland-dxy1300"}) {
    INFO(name);
    const DeviceProfile dev = find_profile(name);
    const bool hpgl = dev.protocol == Protocol::hpgl;
    const Page sheet{dev.machine.sheet_width_mm, dev.machine.sheet_height_mm};
    // An A4-portrait drawing turned a quarter and moved onto the sheet, as lay_out does
    // for a portrait page on a landscape plotter.
    const Affine page_to_sheet = Affine::translate(12, 230) * Affine::rotate_degrees(-90);
    const MachineTransform machine(dev, sheet);
    const double unit = hpgl ? machine.step_mm() : 1.0;
    auto job_point = [&](Vec2 page) {
      const Vec2 m = machine.to_machine_mm(page_to_sheet.apply(page));
      return Vec2{m.x / unit, m.y / unit};
    };
    // A touch at (40, 60) mm and a stroke from (100, 150) to (120, 170) mm on the page.
    const Vec2 touch = job_point({40, 60}), a = job_point({100, 150}), b = job_point({120, 170});
    io::Job job;
    auto line = [&](Vec2 p, bool motion, bool down) {
      io::JobLine l;
      l.motion = motion, l.pen_down = down, l.x = p.x, l.y = p.y;
      job.lines.push_back(l);
    };
    line(touch, true, false), line(touch, false, true), line(touch, false, false);
    line(a, true, false), line(a, false, true), line(b, true, true), line(b, false, false);

    serve::TracePlacement where{210, 297, page_to_sheet};
    const auto t = serve::job_trace(job, dev, hpgl, where);
    REQUIRE(t["segments"].size() == 3);  // the touch, the stroke's start, the stroke
    auto near = [&](const nlohmann::json& s, Vec2 p, Vec2 q) {
      const double tol = unit;  // a device step
      return std::abs(s[1].get<double>() - p.x) <= tol && std::abs(s[2].get<double>() - p.y) <= tol &&
             std::abs(s[3].get<double>() - q.x) <= tol && std::abs(s[4].get<double>() - q.y) <= tol;
    };
    CHECK(near(t["segments"][0], {40, 60}, {40, 60}));
    CHECK(t["segments"][0][0] == 1);  // acknowledged with the pen-down line
    CHECK(near(t["segments"][2], {100, 150}, {120, 170}));
    CHECK(t["page_mm"][0] == 210);
    // Without the layout the marks are where they lie on the sheet: not the page's places.
    const auto flat = serve::job_trace(job, dev, hpgl, serve::TracePlacement{210, 297, Affine{}});
    CHECK_FALSE(near(flat["segments"][2], {100, 150}, {120, 170}));
  }
}

TEST_CASE("the plot trace reads the page and layout from the method's summary", "[serve]") {
  const DeviceProfile dev = find_profile("grbl-servo");
  auto none = serve::placement_from_summary(nullptr, dev);
  CHECK(none.page_w_mm == dev.machine.sheet_width_mm);
  CHECK(none.page_to_sheet.a == 1);
  const nlohmann::json s = {{"page_mm", {210, 297}}, {"layout", {{"transform", {0, -1, 1, 0, 12, 230}}}}};
  auto p = serve::placement_from_summary(s, dev);
  CHECK(p.page_w_mm == 210);
  CHECK(p.page_h_mm == 297);
  CHECK(p.page_to_sheet.b == -1);
  CHECK(p.page_to_sheet.e == 12);
}
