// The viewing-distance measure: blurred in millimetres on paper, whatever the marks.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/bounded_blur.hpp"
#include "eval/view.hpp"
#include "plan/planner.hpp"
#include "preview/preview.hpp"
#include "test_util.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

// A photo with structure at several scales: a ramp with rings.
Image rings(int w, int h) {
  std::vector<uint8_t> g(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double ramp = static_cast<double>(x) / (w - 1), ring = 0.5 + 0.5 * std::sin(std::hypot(x - w / 2.0, y - h / 2.0) / 6);
      g[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(255 * (0.15 + 0.7 * (0.6 * ramp + 0.4 * ring))));
    }
  return Image::from_grey(w, h, g);
}

// A uniform grey photo.
Image flat(int w, int h, uint8_t v) { return Image::from_grey(w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h, v)); }

// Black dots on a square grid of `pitch` mm over the photo's rectangle, each of the
// diameter that lays the darkness of the photo under it (coverage pi d^2 / 4 / pitch^2).
Drawing halftone_drawing(const Image& photo, const PageTransform& tf, double pitch) {
  Drawing d;
  d.page = {tf.page_w(), tf.page_h()};
  Layer l;
  const Vec2 lo = tf.map(0, 0), hi = tf.map(photo.width, photo.height);
  for (double y = lo.y + pitch / 2; y < hi.y; y += pitch)
    for (double x = lo.x + pitch / 2; x < hi.x; x += pitch) {
      const Vec2 p = tf.unmap({x, y});
      const double dark = 1 - photo.channel(static_cast<int>(p.x), static_cast<int>(p.y), 0) / 255.0;
      const double dia = pitch * std::sqrt(4 * dark / M_PI);
      if (dia >= 0.05) l.dots.push_back({{x, y}, dia});
    }
  d.layers.push_back(l);
  return d;
}

Plan halftone(const Image& photo, const PageTransform& tf, double pitch) {
  return plan_drawing(halftone_drawing(photo, tf, pitch), PlanOptions{});
}

}  // namespace

TEST_CASE("a drawing identical to the photo scores SSIM 1 and r 1 at any sigma", "[eval][view]") {
  // 200 x 100 px at 0.1 mm a pixel from (10, 10) mm: the photo lands on the 10 px/mm page grid pixel for pixel.
  const Image photo = rings(200, 100);
  const PageTransform tf(200, 100, PageSpec{40, 30}, 10, false);
  REQUIRE(tf.mm_per_px() == Approx(0.1));
  Image page = flat(400, 300, 255);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x)
      for (int c = 0; c < 3; ++c) page.rgb[((static_cast<size_t>(y) + 100) * 400 + x + 100) * 3 + c] = photo.channel(x, y, c);
  for (double s : {0.25, 0.5, 1.0, 3.0}) {
    ViewOptions o;
    o.sigma_mm = s;
    o.colour = true;
    const ViewScore v = view_score(photo, tf, page, o);
    INFO("sigma " << s);
    CHECK(v.ssim == Approx(1).margin(1e-6));
    CHECK(v.tone_r == Approx(1).margin(1e-6));
    CHECK(v.tone_err == Approx(0).margin(1e-6));
    CHECK(v.delta_e == Approx(0).margin(1e-3));
    CHECK(v.px_per_mm == Approx(10));
  }
}

TEST_CASE("coarse blobs of the right tone score clearly below a fine stipple of it at 0.5 mm", "[eval][view]") {
  const Image photo = flat(300, 200, 191);  // a quarter of the paper to ink
  const PageTransform tf(300, 200, PageSpec{80, 60}, 10, false);
  ViewOptions o;
  o.sigma_mm = 0.5;
  const ViewScore fine = view_score_of_plan(photo, tf, halftone(photo, tf, 0.6), o, 10);
  const ViewScore coarse = view_score_of_plan(photo, tf, halftone(photo, tf, 4.0), o, 10);
  // Both lay the photo's tone ...
  CHECK(fine.mean_drawn == Approx(fine.mean_photo).margin(0.03));
  CHECK(coarse.mean_drawn == Approx(coarse.mean_photo).margin(0.03));
  // ... but the blobs are seen.
  CAPTURE(fine.ssim, coarse.ssim);
  CHECK(fine.ssim > 0.8);
  CHECK(coarse.ssim < fine.ssim - 0.3);
}

TEST_CASE("sigma in mm is independent of the render's resolution", "[eval][view]") {
  const Image photo = load_image(test::example("horse.png"));
  const PageTransform tf(photo.width, photo.height, PageSpec{210, 297}, 10, true);
  const Plan plan = halftone(photo, tf, 0.8);
  for (double s : {0.5, 1.0}) {
    ViewOptions o;
    o.sigma_mm = s;
    const ViewScore at4 = view_score_of_plan(photo, tf, plan, o, 4), at8 = view_score_of_plan(photo, tf, plan, o, 8);
    INFO("sigma " << s << ": SSIM " << at4.ssim << " / " << at8.ssim << ", r " << at4.tone_r << " / " << at8.tone_r);
    CHECK(at4.ssim > 0.5);  // a drawing of the photo, not noise
    CHECK(at4.ssim == Approx(at8.ssim).margin(0.01));
    CHECK(at4.tone_r == Approx(at8.tone_r).margin(0.01));
    CHECK(at4.tone_err == Approx(at8.tone_err).margin(0.01));
  }
}

TEST_CASE("the measure of the drawing, unplanned, agrees with its plan's within 0.02", "[eval][view]") {
  const Image photo = load_image(test::example("coffee.png"));
  const PageTransform tf(photo.width, photo.height, PageSpec{297, 210}, 10, false);
  const Drawing drawing = halftone_drawing(photo, tf, 0.8);
  const Plan plan = plan_drawing(drawing, PlanOptions{});
  for (double s : {0.5, 1.0}) {
    ViewOptions o;
    o.sigma_mm = s;
    const ViewScore p = view_score_of_plan(photo, tf, plan, o), d = view_score_of_drawing(photo, tf, drawing, o);
    INFO("sigma " << s << ": SSIM " << p.ssim << " / " << d.ssim << ", r " << p.tone_r << " / " << d.tone_r);
    CHECK(p.ssim == Approx(d.ssim).margin(0.02));
    CHECK(p.tone_r == Approx(d.tone_r).margin(0.02));
    CHECK(p.tone_err == Approx(d.tone_err).margin(0.02));
  }
}

TEST_CASE("a view sigma is a positive length with its unit", "[eval][view]") {
  CHECK(parse_view_sigma_mm("1mm") == Approx(1));
  CHECK(parse_view_sigma_mm("0.05cm") == Approx(0.5));
  CHECK(parse_view_sigma_mm("2pt") == Approx(2 * 25.4 / 72));
  for (const char* bad : {"-1mm", "0mm", "0.0001mm", "nan", "NaNmm", "1", "mm", "1furlong", "1e9mm", ""}) {
    INFO(bad);
    CHECK_THROWS_AS(parse_view_sigma_mm(bad), UserError);
  }
}

TEST_CASE("eval and the methods' measures refuse a bad --view-sigma in one line", "[eval][view][cli]") {
  test::TempDir t;
  const std::string horse = test::example("horse.png");
  for (const char* bad : {"-1mm", "nan", "0", "0mm", "1"}) {
    const auto r = test::run_cli("eval " + horse + " " + horse + " --cropped --view-sigma " + bad);
    INFO(bad << ": " << r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.err.find("--view-sigma") != std::string::npos);
    CHECK(test::count_lines(r.err) == 1);
  }
  const std::string stipple = "stipple " + horse + " -o " + t.file("h.svg") + " --time 5min";
  auto r = test::run_cli(stipple + " --measure --view-sigma 1");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--view-sigma needs a unit") != std::string::npos);
  r = test::run_cli(stipple + " --view-sigma 1mm");  // nothing to blur for
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("give --measure") != std::string::npos);
  CHECK_FALSE(test::fs::exists(t.file("h.svg")));
}

TEST_CASE("a method's --measure and eval of its SVG give the same viewing-distance figures", "[eval][view][cli]") {
  test::TempDir t;
  const std::string horse = test::example("horse.png");
  auto r = test::run_cli("stipple " + horse + " -o " + t.file("h.svg") + " --time 10min --measure --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto m = nlohmann::json::parse(r.out);
  CHECK(m["view_sigma_mm"].get<double>() == 1);
  r = test::run_cli("eval " + horse + " " + t.file("h.svg") + " --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto e = nlohmann::json::parse(r.out);
  CHECK(e["ssim_view"].get<double>() == Approx(m["ssim_view"].get<double>()).margin(0.01));
  CHECK(e["tone_r_view"].get<double>() == Approx(m["tone_r_view"].get<double>()).margin(0.01));
  CHECK(e["tone_r_view"].get<double>() > 0.5);
  // Closer up the same drawing's marks show more.
  r = test::run_cli("eval " + horse + " " + t.file("h.svg") + " --view-sigma 0.5mm --json");
  REQUIRE(r.exit_code == 0);
  CHECK(nlohmann::json::parse(r.out)["ssim_view"].get<double>() < e["ssim_view"].get<double>());
  // The studio's figure alone: the same SSIM, no colour (its CIEDE2000 a pixel is most of the time).
  r = test::run_cli("eval " + horse + " " + t.file("h.svg") + " --view-only --no-colour --json");
  REQUIRE(r.exit_code == 0);
  const auto nc = nlohmann::json::parse(r.out);
  CHECK(nc["ssim_view"].get<double>() == e["ssim_view"].get<double>());
  CHECK_FALSE(nc.contains("delta_e_view"));
  CHECK(e.contains("delta_e_view"));
  r = test::run_cli("eval " + horse + " " + t.file("h.svg") + " --no-colour --json");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--no-colour goes with --view-only") != std::string::npos);
}

TEST_CASE("the measure is the same bit for bit on one thread and on several", "[eval][view][threads]") {
  const Image photo = load_image(test::example("coffee.png"));
  const PageTransform tf(photo.width, photo.height, PageSpec{150, 100}, 5, false);
  PreviewOptions po;
  po.dpi = 10 * 25.4;  // measure.py's 10 px/mm: 1.5 MP
  const Image page = render_plan(halftone(photo, tf, 0.8), po);
  for (bool colour : {false, true}) {
    ViewOptions o;
    o.colour = colour;
    ViewScore by[3];
    for (int threads : {1, 2, 3}) {
      set_thread_count(threads);
      by[threads - 1] = view_score(photo, tf, page, o);
    }
    set_thread_count(0);
    CAPTURE(colour, by[0].ssim, by[1].ssim);
    CHECK(by[0].ssim > 0.5);
    for (const ViewScore& v : {by[1], by[2]}) {
      CHECK(std::memcmp(&v.ssim, &by[0].ssim, sizeof(double)) == 0);
      CHECK(std::memcmp(&v.tone_r, &by[0].tone_r, sizeof(double)) == 0);
      CHECK(std::memcmp(&v.tone_err, &by[0].tone_err, sizeof(double)) == 0);
      CHECK(std::memcmp(&v.delta_e, &by[0].delta_e, sizeof(double)) == 0);
    }
  }
}

TEST_CASE("the Gaussian blur in bands of rows is the blur of the whole image, bit for bit", "[eval][view][threads]") {
  cv::Mat in(700, 333, CV_64F);
  cv::randu(in, 0.0, 1.0);
  cv::Mat whole, banded;
  set_thread_count(1);
  gaussian_blur_bounded(in, whole, 7.5, cv::BORDER_CONSTANT);
  set_thread_count(3);
  gaussian_blur_bounded(in, banded, 7.5, cv::BORDER_CONSTANT);
  set_thread_count(0);
  REQUIRE(banded.size() == whole.size());
  CHECK(std::memcmp(banded.data, whole.data, whole.total() * sizeof(double)) == 0);
  CHECK(cv::norm(whole, cv::NORM_INF) > 0.3);  // a blur, not an empty image
}

TEST_CASE("the methods' banded blurs (float, in place, wide kernels) are the whole image's, bit for bit", "[eval][threads][blur]") {
  // The methods' cases: the sketch's structure tensor (sigma 1) and ground tone, the
  // hatch's bands and the tree's field (float, replicated border), in place or not, with
  // kernels wider than a band (sigma 40: 241 rows against bands of 128).
  for (const double sigma : {1.0, 2.6, 40.0})
    for (const int rows : {130, 300, 777})
      for (const bool in_place : {false, true}) {
        CAPTURE(sigma, rows, in_place);
        cv::Mat in(rows, 211, CV_32F);
        cv::randu(in, 0.0f, 1.0f);
        cv::Mat whole;
        cv::GaussianBlur(in, whole, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
        set_thread_count(3);
        cv::Mat banded = in_place ? in.clone() : cv::Mat();
        if (in_place)
          gaussian_blur_rows(banded, banded, sigma, cv::BORDER_REPLICATE);
        else
          gaussian_blur_rows(in, banded, sigma, cv::BORDER_REPLICATE);
        set_thread_count(0);
        REQUIRE(banded.size() == whole.size());
        CHECK(std::memcmp(banded.data, whole.data, whole.total() * sizeof(float)) == 0);
        CHECK(std::memcmp(banded.data, in.data, in.total() * sizeof(float)) != 0);  // blurred at all
      }
}
