#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "image/image.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

using namespace stipplot;

namespace {
std::vector<uint8_t> rgba_pattern(int w, int h) {
  std::vector<uint8_t> p(static_cast<size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* q = &p[(static_cast<size_t>(y) * w + x) * 4];
      q[0] = static_cast<uint8_t>(x * 8);
      q[1] = static_cast<uint8_t>(y * 8);
      q[2] = 100;
      q[3] = x < w / 2 ? 255 : 0;  // right half fully transparent
    }
  return p;
}
}  // namespace

TEST_CASE("PNG, BMP, TGA and JPEG load, alpha composites on white", "[image]") {
  test::TempDir t;
  const int w = 16, h = 8;
  auto px = rgba_pattern(w, h);
  REQUIRE(stbi_write_png(t.file("a.png").c_str(), w, h, 4, px.data(), w * 4));
  REQUIRE(stbi_write_bmp(t.file("a.bmp").c_str(), w, h, 4, px.data()));
  REQUIRE(stbi_write_tga(t.file("a.tga").c_str(), w, h, 4, px.data()));
  REQUIRE(stbi_write_jpg(t.file("a.jpg").c_str(), w, h, 4, px.data(), 95));
  for (const char* f : {"a.png", "a.bmp", "a.tga"}) {
    Image im = load_image(t.file(f));
    REQUIRE(im.width == w);
    REQUIRE(im.height == h);
    CHECK(im.channel(3, 2, 0) == 24);
    CHECK(im.channel(3, 2, 1) == 16);
    if (std::string(f) != "a.bmp") {  // BMP writer drops alpha
      CHECK(im.channel(12, 2, 0) == 255);  // transparent -> white
      CHECK(im.channel(12, 2, 2) == 255);
    }
  }
  Image j = load_image(t.file("a.jpg"));
  CHECK(j.width == w);
}

TEST_CASE("an RGB photo decodes to its pixels exactly (the decoder's own buffer, taken as it is)", "[image]") {
  test::TempDir t;
  const int w = 7, h = 5;
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>(i * 37 + 11);
  REQUIRE(stbi_write_png(t.file("rgb.png").c_str(), w, h, 3, px.data(), w * 3));
  const Image im = load_image(t.file("rgb.png"));
  REQUIRE(im.rgb.size() == px.size());
  CHECK(std::equal(px.begin(), px.end(), im.rgb.begin()));
}

TEST_CASE("an image's bytes behave as a vector's: zero-filled growth, deep copies, emptied moves", "[image]") {
  PixelBytes a;
  CHECK(a.empty());
  a.resize(4);
  CHECK(std::vector<uint8_t>(a.begin(), a.end()) == std::vector<uint8_t>{0, 0, 0, 0});
  a[1] = 9;
  a.resize(6);  // keeps what was there, the new bytes read 0
  CHECK(std::vector<uint8_t>(a.begin(), a.end()) == std::vector<uint8_t>{0, 9, 0, 0, 0, 0});
  PixelBytes b = a;
  b[0] = 5;
  CHECK(a[0] == 0);  // a copy of its own
  CHECK_FALSE(a == b);
  b = a;
  CHECK(a == b);
  PixelBytes c = std::move(b);
  CHECK(b.empty());
  CHECK(c == a);
  c.assign(3, 7);
  CHECK(std::vector<uint8_t>(c.begin(), c.end()) == std::vector<uint8_t>{7, 7, 7});
  c.assign(c.data() + 1, c.data() + 3);  // from its own bytes
  CHECK(std::vector<uint8_t>(c.begin(), c.end()) == std::vector<uint8_t>{7, 7});
  c.resize(0);
  CHECK(c.empty());
  CHECK(c == PixelBytes{});
}

TEST_CASE("luma is Rec. 601", "[image]") {
  CHECK(luma601(255, 0, 0) == 76);
  CHECK(luma601(0, 255, 0) == 150);
  CHECK(luma601(0, 0, 255) == 29);
  CHECK(luma601(255, 255, 255) == 255);
  Image im = Image::from_grey(2, 1, {10, 200});
  CHECK(im.luma() == std::vector<uint8_t>{10, 200});
  CHECK(im.plane(1) == std::vector<uint8_t>{10, 200});
}

TEST_CASE("bad image files give one clear error each", "[image][bad-input]") {
  test::TempDir t;
  auto px = rgba_pattern(40, 40);
  REQUIRE(stbi_write_png(t.file("ok.png").c_str(), 40, 40, 4, px.data(), 160));
  std::string png = test::read_file(t.file("ok.png"));
  { std::ofstream(t.file("empty.png")); }
  { std::ofstream(t.file("text.png")) << "this is not an image\n"; }
  { std::ofstream(t.file("trunc.png"), std::ios::binary) << png.substr(0, png.size() / 2); }
  CHECK_THROWS_WITH(load_image(t.file("missing.png")), Catch::Contains("no such file"));
  CHECK_THROWS_WITH(load_image(t.file("empty.png")), Catch::Contains("empty"));
  CHECK_THROWS_WITH(load_image(t.file("text.png")), Catch::Contains("not a readable image"));
  CHECK_THROWS_WITH(load_image(t.file("trunc.png")), Catch::Contains("truncated"));
  CHECK_THROWS_WITH(load_image(t.path.string()), Catch::Contains("directory"));
  LoadOptions lo;
  lo.max_pixels = 1000;
  CHECK_THROWS_WITH(load_image(t.file("ok.png"), lo), Catch::Contains("--max-pixels"));
  // A header claiming a gigantic image: test_codecs.cpp.
}
