// The plot-time budget as a user meets it: every method command plans its drawing to fit
// --time on the profile (planned time <= the budget, and >= 0.8 of it where the image can
// use it), and the same page and pen give the same drawing whatever the input's size.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "preview/preview.hpp"
#include "test_util.hpp"

namespace {

std::string example(const char* name) { return std::string(STIPPLOT_SOURCE_DIR) + "/examples/" + name; }

nlohmann::json run_json(const std::string& args) {
  const auto r = test::run_cli(args + " --json");
  INFO(args << "\n" << r.err);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(r.out);
}

// The input resampled by `scale` (area averaging down, cubic up), written as PNG.
std::string scaled_copy(const test::TempDir& t, const std::string& src, double scale, const std::string& name) {
  const stipplot::Image in = stipplot::load_image(src);
  stipplot::Image out;
  out.width = static_cast<int>(in.width * scale);
  out.height = static_cast<int>(in.height * scale);
  out.rgb.resize(out.pixels() * 3);
  const cv::Mat a(in.height, in.width, CV_8UC3, const_cast<uint8_t*>(in.rgb.data()));
  cv::Mat b(out.height, out.width, CV_8UC3, out.rgb.data());
  cv::resize(a, b, b.size(), 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_CUBIC);
  stipplot::write_png(out, t.file(name));
  return t.file(name);
}

}  // namespace

TEST_CASE("the planned plot fits the budget and uses it: 15 min, 1 h, 4 h on two profiles", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = example("coffee.png");
  for (const char* profile : {"grbl-servo", "hp7475a-a4"}) {
    for (const char* time : {"15min", "1h", "4h"}) {
      const double budget = std::string(time) == "15min" ? 900 : std::string(time) == "1h" ? 3600 : 14400;
      const auto j = run_json("stipple " + img + " -o " + t.file("b.svg") + " --profile " + profile + " --time " + time);
      const double planned = j["plan"]["total"]["seconds"].get<double>();
      INFO(profile << " " << time << ": planned " << planned << " s, knob " << j["budget"]["knob"]);
      CHECK(planned <= budget);
      // The finest drawing (every dot one pen touch at the spacing of the tone) is all
      // an image can use: below that the budget must be used.
      if (!j["budget"]["finest"].get<bool>()) CHECK(planned >= 0.8 * budget);
      CHECK(j["budget"]["seconds"].get<double>() == budget);
    }
  }
}

TEST_CASE("the same page and pen give the same marks whatever the input's resolution", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = example("coffee.png");
  const std::string quarter = scaled_copy(t, img, 0.25, "q.png"), four = scaled_copy(t, img, 4, "x4.png");
  const std::string opts = " -o " + t.file("r.svg") + " --time 30min";
  const auto base = run_json("stipple " + img + opts);
  const double n = base["primitives"].get<double>();
  for (const std::string& other : {quarter, four}) {
    const auto j = run_json("stipple " + other + opts);
    INFO(other << ": " << j["primitives"] << " marks against " << n);
    CHECK(std::abs(j["primitives"].get<double>() - n) <= 0.05 * n);
  }
}
