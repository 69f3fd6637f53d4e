#include <catch2/catch.hpp>
#include <algorithm>
#include <set>

#include "methods/stipple/pds.hpp"
#include "methods/stipple/stipple.hpp"
#include "test_util.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

std::vector<uint8_t> noise_image(int w, int h, uint64_t seed) {
  Rng rng(seed);
  std::vector<uint8_t> d(static_cast<size_t>(w) * h);
  // smooth-ish: blocks of random levels plus per-pixel jitter
  std::vector<uint8_t> blocks(static_cast<size_t>((w / 8 + 1) * (h / 8 + 1)));
  for (auto& b : blocks) b = static_cast<uint8_t>(rng.below(256));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      d[static_cast<size_t>(y) * w + x] =
          static_cast<uint8_t>(std::clamp<int>(blocks[static_cast<size_t>((y / 8) * (w / 8 + 1) + x / 8)] +
                                                   static_cast<int>(rng.below(21)) - 10,
                                               0, 255));
  return d;
}

int64_t d2(uint32_t a, uint32_t b, int w) {
  int64_t ax = a % w, ay = a / w, bx = b % w, by = b / w;
  return (ax - bx) * (ax - bx) + (ay - by) * (ay - by);
}

// The paper's rule, checked by brute force: each dot had no earlier dot within its
// radius, and each pixel without a dot had one within its radius (then and so now).
void check_pds_rule(const std::vector<uint8_t>& d, int w, const pds::RadiusTable& rt,
                    const std::vector<uint32_t>& dots) {
  std::vector<char> has(d.size(), 0);
  for (size_t i = 0; i < dots.size(); ++i) {
    has[dots[i]] = 1;
    for (size_t j = 0; j < i; ++j) REQUIRE(static_cast<double>(d2(dots[i], dots[j], w)) > rt.r2[d[dots[i]]]);
  }
  for (uint32_t p = 0; p < d.size(); ++p) {
    if (has[p]) continue;
    bool blocked = false;
    for (uint32_t q : dots)
      if (static_cast<double>(d2(p, q, w)) <= rt.r2[d[p]]) {
        blocked = true;
        break;
      }
    REQUIRE(blocked);
  }
}

}  // namespace

TEST_CASE("grayscale order is a permutation, dark first, ties shuffled by the seed", "[pds]") {
  auto d = noise_image(64, 48, 3);
  Rng r1(1), r2(2);
  auto o1 = pds::grayscale_order(d, r1), o2 = pds::grayscale_order(d, r2);
  std::vector<uint32_t> sorted = o1;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t i = 0; i < sorted.size(); ++i) REQUIRE(sorted[i] == i);
  for (size_t i = 1; i < o1.size(); ++i) REQUIRE(d[o1[i - 1]] <= d[o1[i]]);
  CHECK(o1 != o2);  // different seeds break ties differently
  Rng r1b(1);
  CHECK(pds::grayscale_order(d, r1b) == o1);
}

TEST_CASE("grayscale order of a million pixels: the same on 1 to 3 threads as one plain pass and the stream left where it leaves it", "[pds][threads]") {
  // A third of the pixels white (one level larger than a thread's share), the rest noise.
  const int w = 1100, h = 1000;
  std::vector<uint8_t> d = noise_image(w, h, 9);
  for (size_t i = 0; i < d.size(); i += 3) d[i] = 255;
  // The plain pass: a stable counting sort, then Fisher-Yates level after level.
  Rng plain(4);
  std::vector<uint32_t> expect(d.size());
  std::vector<size_t> start(257, 0);
  for (uint8_t v : d) ++start[v + 1u];
  for (int v = 0; v < 256; ++v) start[v + 1] += start[v];
  std::vector<size_t> fill(start.begin(), start.end() - 1);
  for (size_t i = 0; i < d.size(); ++i) expect[fill[d[i]]++] = static_cast<uint32_t>(i);
  for (int v = 0; v < 256; ++v)
    for (size_t i = start[v + 1] - start[v]; i > 1; --i)
      std::swap(expect[start[v] + i - 1], expect[start[v] + plain.below(static_cast<uint32_t>(i))]);
  const uint64_t after = plain.next();
  for (int threads : {1, 2, 3}) {
    set_thread_count(threads);
    Rng rng(4);
    const std::vector<uint32_t> got = pds::grayscale_order(d, rng);
    INFO(threads << " threads");
    CHECK((got == expect));  // (not decomposed: Catch would print a million numbers)
    CHECK(rng.next() == after);
  }
  set_thread_count(0);
}

TEST_CASE("random order is a uniform-looking permutation", "[pds]") {
  Rng rng(5);
  auto o = pds::random_order(10000, rng);
  std::vector<uint32_t> s = o;
  std::sort(s.begin(), s.end());
  for (uint32_t i = 0; i < s.size(); ++i) REQUIRE(s[i] == i);
  // the first tenth is spread over the whole range, not a prefix
  uint32_t maxfirst = *std::max_element(o.begin(), o.begin() + 1000);
  CHECK(maxfirst > 9000);
}

TEST_CASE("DotGrid answers like a brute-force scan", "[pds]") {
  for (double spacing : {0.0, 1.0, 2.0, 3.5, 7.0}) {
    const int w = 97, h = 61;
    pds::DotGrid g(w, h, spacing);
    std::vector<std::pair<int, int>> dots;
    Rng rng(11);
    // insert random dots that respect the spacing
    for (int k = 0; k < 4000; ++k) {
      int x = static_cast<int>(rng.below(w)), y = static_cast<int>(rng.below(h));
      bool ok = true;
      for (auto [px, py] : dots)
        if (std::hypot(px - x, py - y) <= std::max(spacing, 0.5)) ok = false;
      if (ok) {
        g.insert(x, y);
        dots.emplace_back(x, y);
      }
    }
    for (int k = 0; k < 3000; ++k) {
      int x = static_cast<int>(rng.below(w)), y = static_cast<int>(rng.below(h));
      double r = rng.uniform() * 12;
      bool brute = false;
      for (auto [px, py] : dots)
        if ((px - x) * (px - x) + (py - y) * (py - y) <= r * r) brute = true;
      REQUIRE(g.any_within(x, y, r, r * r) == brute);
    }
  }
}

TEST_CASE("grayscale-order and random-order PDS follow the paper's rule", "[pds]") {
  const int w = 60, h = 40;
  auto d = noise_image(w, h, 9);
  for (auto [a, b] : std::vector<std::pair<double, double>>{{1, 4}, {2, 8}, {0, 3}, {3, 15}}) {
    auto rt = pds::RadiusTable::linear(a, b, false);
    Rng r1(4), r2(4);
    check_pds_rule(d, w, rt, pds::sample(w, h, d, rt, pds::grayscale_order(d, r1)));
    check_pds_rule(d, w, rt, pds::sample(w, h, d, rt, pds::random_order(d.size(), r2)));
  }
}

TEST_CASE("the first pixel visited always gets a dot", "[pds]") {
  std::vector<uint8_t> d(50 * 50, 200);
  auto rt = pds::RadiusTable::linear(3, 15, false);
  Rng rng(8);
  auto order = pds::grayscale_order(d, rng);
  auto dots = pds::sample(50, 50, d, rt, order);
  REQUIRE(!dots.empty());
  CHECK(dots[0] == order[0]);
}

TEST_CASE("binary stippling: no pixel holds both colours, each colour keeps its radius", "[pds][binary]") {
  const int w = 50, h = 40;
  auto d = noise_image(w, h, 21);
  auto s = pds::RadiusTable::linear(1, 5, false), t = pds::RadiusTable::linear(1.5, 4, true);
  Rng rng(3);
  auto order = pds::grayscale_order(d, rng);
  auto r = pds::sample_binary(w, h, d, s, t, order);
  std::set<uint32_t> black(r.black.begin(), r.black.end());
  for (uint32_t i : r.white) REQUIRE(black.count(i) == 0);
  REQUIRE(!r.black.empty());
  REQUIRE(!r.white.empty());
  for (size_t i = 0; i < r.black.size(); ++i)
    for (size_t j = 0; j < i; ++j) REQUIRE(static_cast<double>(d2(r.black[i], r.black[j], w)) > s.r2[d[r.black[i]]]);
  for (size_t i = 0; i < r.white.size(); ++i)
    for (size_t j = 0; j < i; ++j) REQUIRE(static_cast<double>(d2(r.white[i], r.white[j], w)) > t.r2[d[r.white[i]]]);
  // black dots go dark first, white dots bright first
  double mean_black = 0, mean_white = 0;
  for (uint32_t i : r.black) mean_black += d[i];
  for (uint32_t i : r.white) mean_white += d[i];
  CHECK(mean_black / r.black.size() < mean_white / r.white.size());
}

TEST_CASE("stippling is deterministic for a seed, bit for bit", "[stipple]") {
  Image img = Image::from_grey(80, 60, noise_image(80, 60, 2));
  for (const char* m : {"random", "gray", "negative", "binary", "color", "cmyk"}) {
    StippleParams p;
    p.method = parse_stipple_method(m);
    p.a = 1;
    p.b = 6;
    p.seed = 42;
    auto a = stipple_pixels(img, p), b = stipple_pixels(img, p);
    REQUIRE(a.layers.size() == b.layers.size());
    for (size_t l = 0; l < a.layers.size(); ++l) REQUIRE(a.layers[l].dots == b.layers[l].dots);
    p.seed = 43;
    auto c = stipple_pixels(img, p);
    bool differs = c.layers.size() != a.layers.size();
    for (size_t l = 0; !differs && l < a.layers.size(); ++l) differs = a.layers[l].dots != c.layers[l].dots;
    CHECK(differs);
  }
}

TEST_CASE("negative stippling is grayscale stippling of the inverted image", "[stipple]") {
  auto d = noise_image(70, 50, 6);
  std::vector<uint8_t> inv(d.size());
  for (size_t i = 0; i < d.size(); ++i) inv[i] = static_cast<uint8_t>(255 - d[i]);
  StippleParams p;
  p.a = 1;
  p.b = 5;
  p.method = StippleMethod::Negative;
  auto neg = stipple_pixels(Image::from_grey(70, 50, d), p);
  p.method = StippleMethod::Gray;
  auto pos = stipple_pixels(Image::from_grey(70, 50, inv), p);
  REQUIRE(neg.layers.size() == 1);
  CHECK(neg.paper == colors::black);
  CHECK(neg.layers[0].pen.color == colors::white);
  CHECK(neg.layers[0].dots == pos.layers[0].dots);
}

TEST_CASE("colour stippling uses only the 26 dot colours of the 27-colour palette", "[stipple][color]") {
  Image img;
  img.width = 64;
  img.height = 64;
  img.rgb.resize(64 * 64 * 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      size_t o = (static_cast<size_t>(y) * 64 + x) * 3;
      img.rgb[o] = static_cast<uint8_t>(x * 4);
      img.rgb[o + 1] = static_cast<uint8_t>(y * 4);
      img.rgb[o + 2] = static_cast<uint8_t>(255 - x * 2);
    }
  StippleParams p;
  p.method = StippleMethod::Color;
  p.a_b = p.a_w = 1;
  p.b_b = p.b_w = 4;
  auto r = stipple_pixels(img, p);
  CHECK(r.paper == Color{128, 128, 128});
  REQUIRE(r.layers.size() > 5);
  REQUIRE(r.layers.size() <= 26);
  std::set<uint32_t> seen;
  for (const auto& l : r.layers) {
    for (uint8_t c : {l.pen.color.r, l.pen.color.g, l.pen.color.b}) REQUIRE((c == 0 || c == 128 || c == 255));
    REQUIRE(!(l.pen.color == Color{128, 128, 128}));
    for (uint32_t i : l.dots) REQUIRE(seen.insert(i).second);  // one colour a pixel
  }
}

TEST_CASE("CMYK separation gives one pen layer per ink, denser where that ink is needed", "[stipple][cmyk]") {
  // left half pure cyan (R=0), right half pure yellow (B=0)
  Image img;
  img.width = 80;
  img.height = 40;
  img.rgb.resize(80 * 40 * 3);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 80; ++x) {
      size_t o = (static_cast<size_t>(y) * 80 + x) * 3;
      bool left = x < 40;
      img.rgb[o] = left ? 0 : 255;
      img.rgb[o + 1] = 255;
      img.rgb[o + 2] = left ? 255 : 0;
    }
  StippleParams p;
  p.method = StippleMethod::Cmyk;
  p.a = 1;
  p.b = 6;
  auto r = stipple_pixels(img, p);
  REQUIRE(r.layers.size() == 4);
  CHECK(r.layers[0].pen.name == "cyan");
  CHECK(r.layers[3].pen.name == "black");
  auto left_share = [&](const StippleLayer& l) {
    size_t left = 0;
    for (uint32_t i : l.dots) left += (i % 80) < 40;
    return l.dots.empty() ? 0.5 : static_cast<double>(left) / static_cast<double>(l.dots.size());
  };
  CHECK(left_share(r.layers[0]) > 0.75);  // cyan on the cyan half
  CHECK(left_share(r.layers[2]) < 0.25);  // yellow on the yellow half
}

TEST_CASE("bad stippling parameters are rejected with their names", "[stipple]") {
  Image img = Image::from_grey(10, 10, std::vector<uint8_t>(100, 100));
  StippleParams p;
  p.a = -1;
  CHECK_THROWS_WITH(stipple_pixels(img, p), Catch::Contains("-a"));
  p.a = std::nan("");
  CHECK_THROWS_WITH(stipple_pixels(img, p), Catch::Contains("-a"));
  p.a = 1;
  p.b_w = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(stipple_pixels(img, p), Catch::Contains("--b-w"));
  CHECK_THROWS_WITH(parse_stipple_method("pointy"), Catch::Contains("pointy"));
}
