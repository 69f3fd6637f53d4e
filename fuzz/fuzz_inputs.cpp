#include "fuzz/fuzz_inputs.hpp"

#include "drivers/device/profile.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/job/segments.hpp"
#include "image/image.hpp"
#include "methods/palette.hpp"
#include "plan/planner.hpp"
#include "svg/svg_reader.hpp"
#include "util/error.hpp"

namespace stipplot::fuzz {

namespace {

std::string text_of(const uint8_t* d, size_t n) { return std::string(reinterpret_cast<const char*>(d), n); }

template <class F>
void answering(F&& f) {
  try {
    f();
  } catch (const UserError&) {
  }
}

void svg(const uint8_t* d, size_t n) {
  answering([&] {
    // Lower caps than a user's: each input stays quick, the caps themselves are tested.
    SvgReadOptions ro;
    ro.max_use_copies = 20000;
    ro.max_points = 200000;
    const Drawing drawing = parse_svg(text_of(d, n), "fuzz.svg", ro);
    if (drawing.primitive_count() > 2000) return;
    PlanOptions po;
    po.optimize_effort = 0;
    po.optimize_seconds = 1;
    (void)plan_drawing(drawing, po);
  });
}

void gcode(const uint8_t* d, size_t n) {
  answering([&] {
    io::GcodePenRule rule;
    rule.servo_up_s = n > 0 ? d[0] % 3 * 500 : 0;  // servo, laser and Z-axis rules
    (void)io::job_segments(io::parse_gcode_job(text_of(d, n), rule));
  });
}

void hpgl(const uint8_t* d, size_t n) {
  answering([&] { (void)io::job_segments(io::parse_hpgl_job(text_of(d, n))); });
}

// An EiBotBoard job: its lines, the pen-down segments and the firmware time of each line.
void ebb(const uint8_t* d, size_t n) {
  answering([&] {
    const io::Job job = io::parse_ebb_job(text_of(d, n), 80);
    (void)io::job_segments(job);
    (void)io::time_ebb_job(job);
  });
}

void profile(const uint8_t* d, size_t n) {
  answering([&] { (void)parse_profile(text_of(d, n), "fuzz.toml"); });
}

void palette(const uint8_t* d, size_t n) {
  answering([&] { (void)parse_palette(text_of(d, n), "fuzz.toml"); });
}

void image(const uint8_t* d, size_t n) {
  answering([&] {
    LoadOptions lo;
    lo.max_pixels = 4'000'000;  // a header may claim anything: refused before decoding
    (void)decode_image(d, n, "fuzz.img", lo);
  });
}

}  // namespace

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {{"svg", svg},         {"gcode", gcode},     {"hpgl", hpgl},
                                          {"ebb", ebb},         {"profile", profile}, {"palette", palette},
                                          {"image", image}};
  return all;
}

const Target* find_target(const std::string& name) {
  for (const Target& t : targets())
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace stipplot::fuzz
