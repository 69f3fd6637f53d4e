// The PNG and JPEG readers (libpng, libjpeg-turbo: src/image/codec.c) against stb_image,
// which read every image before them: the same pixels for every PNG layout, the same
// photo within the JPEG standard's rounding, and damage reported, never filled in.
#include <catch2/catch.hpp>

#include <jpeglib.h>
#include <png.h>
#include <stb_image.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "image/image.hpp"
#include "util/error.hpp"

using namespace stipplot;

namespace {

using Bytes = std::vector<uint8_t>;

void append(png_structp png, png_bytep data, size_t n) {
  auto* out = static_cast<Bytes*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}

// A PNG of the given layout whose samples run through every value (a stride coprime with
// the depth's range), with a transparent colour or palette entries when asked.
Bytes make_png(uint32_t w, uint32_t h, int color, int depth, bool interlaced, bool transparent) {
  Bytes file;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  REQUIRE((png && info));
  png_set_write_fn(png, &file, append, nullptr);
  png_set_IHDR(png, info, w, h, depth, color, interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  const int max = (1 << depth) - 1;
  if (color == PNG_COLOR_TYPE_PALETTE) {
    std::vector<png_color> pal(static_cast<size_t>(max) + 1);
    for (size_t i = 0; i < pal.size(); ++i)
      pal[i] = {static_cast<png_byte>(i * 37 + 5), static_cast<png_byte>(i * 91 + 17), static_cast<png_byte>(255 - i * 13)};
    png_set_PLTE(png, info, pal.data(), static_cast<int>(pal.size()));
    if (transparent) {
      std::vector<png_byte> alpha(pal.size());
      for (size_t i = 0; i < alpha.size(); ++i) alpha[i] = static_cast<png_byte>(i * 61);
      png_set_tRNS(png, info, alpha.data(), static_cast<int>(alpha.size()), nullptr);
    }
  } else if (transparent) {
    png_color_16 key{};
    key.gray = key.red = static_cast<png_uint_16>(max / 3);
    key.green = static_cast<png_uint_16>(max / 5);
    key.blue = static_cast<png_uint_16>(max / 7);
    png_set_tRNS(png, info, nullptr, 0, &key);
  }
  png_write_info(png, info);
  const int channels = png_get_channels(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  std::vector<Bytes> rows(h, Bytes(row_bytes));
  uint32_t v = 1;
  for (uint32_t y = 0; y < h; ++y) {
    if (depth < 8) {  // packed samples: any bits are valid indices or greys
      for (auto& b : rows[y]) {
        v = v * 1103515245u + 12345u;
        b = static_cast<uint8_t>(v >> 16);
      }
      continue;
    }
    const size_t samples = static_cast<size_t>(w) * static_cast<size_t>(channels);
    for (size_t s = 0; s < samples; ++s) {
      v = v * 1103515245u + 12345u;
      const unsigned value = (v >> 8) % static_cast<unsigned>(max + 1);
      if (depth == 16) {
        rows[y][s * 2] = static_cast<uint8_t>(value >> 8);
        rows[y][s * 2 + 1] = static_cast<uint8_t>(value);
      } else {
        rows[y][s] = static_cast<uint8_t>(value);
      }
    }
    // The transparent colour itself, so the key is hit.
    if (transparent && color != PNG_COLOR_TYPE_PALETTE && depth == 8)
      for (int c = 0; c < channels; ++c)
        rows[y][static_cast<size_t>(c)] = static_cast<uint8_t>(c == 0 ? max / 3 : c == 1 ? max / 5 : max / 7);
  }
  std::vector<png_bytep> pointers;
  for (auto& r : rows) pointers.push_back(r.data());
  png_write_image(png, pointers.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return file;
}

// stb_image's reading of a file, alpha composited on white as stipplot does.
Bytes stb_on_white(const Bytes& file, int* w, int* h) {
  int comp = 0;
  unsigned char* p = stbi_load_from_memory(file.data(), static_cast<int>(file.size()), w, h, &comp, 4);
  REQUIRE(p);
  const size_t n = static_cast<size_t>(*w) * static_cast<size_t>(*h);
  Bytes rgb(n * 3);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) {
      const unsigned a = p[i * 4 + 3];
      rgb[i * 3 + c] = static_cast<uint8_t>((p[i * 4 + c] * a + 255u * (255u - a) + 127u) / 255u);
    }
  stbi_image_free(p);
  return rgb;
}

Bytes decoded(const Bytes& file) {
  const Image im = decode_image(file.data(), file.size(), "test");
  return Bytes(im.rgb.begin(), im.rgb.end());
}

struct Layout {
  int color;
  std::vector<int> depths;
};

// `samples` (rows of `components` bytes a pixel: 1 grey, 3 RGB, 4 CMYK with Adobe's marker,
// as Photoshop writes it) as a JPEG, written by libjpeg-turbo itself.
Bytes encode_jpeg(const Bytes& samples, int w, int h, int components, int quality, bool progressive,
                  const Bytes& exif = {}) {
  jpeg_compress_struct ci{};
  jpeg_error_mgr err{};
  ci.err = jpeg_std_error(&err);
  jpeg_create_compress(&ci);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&ci, &out, &size);
  ci.image_width = static_cast<JDIMENSION>(w);
  ci.image_height = static_cast<JDIMENSION>(h);
  ci.input_components = components;
  ci.in_color_space = components == 1 ? JCS_GRAYSCALE : components == 3 ? JCS_RGB : JCS_CMYK;
  jpeg_set_defaults(&ci);
  jpeg_set_quality(&ci, quality, TRUE);
  if (progressive) jpeg_simple_progression(&ci);
  jpeg_start_compress(&ci, TRUE);
  if (!exif.empty()) jpeg_write_marker(&ci, JPEG_APP0 + 1, exif.data(), static_cast<unsigned>(exif.size()));
  const size_t stride = static_cast<size_t>(w) * static_cast<size_t>(components);
  while (ci.next_scanline < ci.image_height) {
    JSAMPROW r = const_cast<uint8_t*>(&samples[static_cast<size_t>(ci.next_scanline) * stride]);
    jpeg_write_scanlines(&ci, &r, 1);
  }
  jpeg_finish_compress(&ci);
  jpeg_destroy_compress(&ci);
  Bytes file(out, out + size);
  std::free(out);
  return file;
}

// Every pixel `sample` (`components` bytes).
Bytes make_jpeg(int w, int h, int components, const uint8_t* sample) {
  Bytes px(static_cast<size_t>(w) * static_cast<size_t>(h) * static_cast<size_t>(components));
  for (size_t i = 0; i < px.size(); ++i) px[i] = sample[i % static_cast<size_t>(components)];
  return encode_jpeg(px, w, h, components, 95, false);
}

// A smooth photo-like image (three gradients), for JPEGs.
Bytes gradient_rgb(int w, int h) {
  Bytes px(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &px[(static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)) * 3];
      p[0] = static_cast<uint8_t>(x * 255 / (w - 1));
      p[1] = static_cast<uint8_t>(y * 255 / (h - 1));
      p[2] = static_cast<uint8_t>((x + y) * 255 / (w + h - 2));
    }
  return px;
}

Bytes jpeg_of(const Bytes& rgb, int w, int h, bool progressive) { return encode_jpeg(rgb, w, h, 3, 90, progressive); }

}  // namespace

TEST_CASE("every PNG layout decodes to stb_image's pixels, interlaced or not", "[image][codec]") {
  const std::vector<Layout> layouts = {{PNG_COLOR_TYPE_GRAY, {1, 2, 4, 8, 16}},
                                       {PNG_COLOR_TYPE_GRAY_ALPHA, {8, 16}},
                                       {PNG_COLOR_TYPE_RGB, {8, 16}},
                                       {PNG_COLOR_TYPE_RGB_ALPHA, {8, 16}},
                                       {PNG_COLOR_TYPE_PALETTE, {1, 2, 4, 8}}};
  int checked = 0;
  for (const Layout& l : layouts)
    for (int depth : l.depths)
      for (bool interlaced : {false, true})
        for (bool transparent : {false, true}) {
          if (transparent && (l.color & PNG_COLOR_MASK_ALPHA)) continue;  // tRNS is not allowed there
          CAPTURE(l.color, depth, interlaced, transparent);
          const Bytes file = make_png(37, 23, l.color, depth, interlaced, transparent);
          int w = 0, h = 0;
          const Bytes expect = stb_on_white(file, &w, &h);
          REQUIRE((w == 37 && h == 23));
          CHECK((decoded(file) == expect));
          ++checked;
        }
  CHECK(checked == 52);
}

TEST_CASE("a JPEG decodes as stb_image decodes it, to the rounding of the standard's IDCT", "[image][codec]") {
  const int w = 67, h = 45;
  const Bytes rgb = gradient_rgb(w, h);
  for (bool progressive : {false, true}) {
    CAPTURE(progressive);
    const Bytes file = jpeg_of(rgb, w, h, progressive);
    int sw = 0, sh = 0;
    const Bytes expect = stb_on_white(file, &sw, &sh);
    const Bytes got = decoded(file);
    REQUIRE(got.size() == expect.size());
    long sum = 0;
    int worst = 0;
    for (size_t i = 0; i < got.size(); ++i) {
      const int d = std::abs(int(got[i]) - int(expect[i]));
      sum += d;
      worst = std::max(worst, d);
    }
    // The two decoders' IDCT and chroma upsampling round differently (measured on the
    // 12-MP benchmark photo: mean 0.05, largest 3 levels).
    CHECK(double(sum) / double(got.size()) < 0.5);
    CHECK(worst <= 6);
    // And both are the photo, within the quality's loss.
    long err = 0;
    for (size_t i = 0; i < got.size(); ++i) err += std::abs(int(got[i]) - int(rgb[i]));
    CHECK(double(err) / double(got.size()) < 4.0);
  }
}

TEST_CASE("grey and Adobe CMYK JPEGs decode to RGB as stb_image decodes them", "[image][codec]") {
  const uint8_t grey[1] = {77};
  const Bytes g = decoded(make_jpeg(24, 16, 1, grey));
  REQUIRE(g.size() == 24u * 16u * 3u);
  for (uint8_t v : g) CHECK(std::abs(int(v) - 77) <= 1);
  // Stored inverted (255 = no ink), as Photoshop writes CMYK: cyan-free, half magenta,
  // full yellow, no black reads (255, 128, 0); with half black, about half of each.
  for (const auto& cmyk : {std::vector<uint8_t>{255, 128, 0, 255}, std::vector<uint8_t>{255, 128, 0, 128}}) {
    const Bytes file = make_jpeg(24, 16, 4, cmyk.data());
    int w = 0, h = 0;
    const Bytes expect = stb_on_white(file, &w, &h);
    const Bytes got = decoded(file);
    REQUIRE(got.size() == expect.size());
    for (size_t i = 0; i < got.size(); ++i) CHECK(std::abs(int(got[i]) - int(expect[i])) <= 2);
    const double k = cmyk[3] / 255.0;
    CHECK(std::abs(got[0] - 255 * k) <= 3);
    CHECK(std::abs(got[1] - 128 * k) <= 3);
    CHECK(got[2] <= 3);
  }
}

TEST_CASE("a cut or damaged PNG or JPEG is an error naming it, never a grey fill", "[image][codec][bad-input]") {
  const Bytes png = make_png(64, 64, PNG_COLOR_TYPE_RGB, 8, false, false);
  const Bytes jpeg = jpeg_of(gradient_rgb(64, 64), 64, 64, false);
  const Bytes progressive = jpeg_of(gradient_rgb(64, 64), 64, 64, true);
  auto fails = [](const Bytes& file, size_t keep, const char* what) {
    const Bytes cut(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(keep));
    CHECK_THROWS_WITH(decode_image(cut.data(), cut.size(), "cut"), Catch::Contains(std::string("truncated or corrupt ") + what));
  };
  for (size_t keep : {size_t{10}, size_t{40}, png.size() / 2, png.size() - 20}) fails(png, keep, "PNG");
  for (size_t keep : {size_t{4}, size_t{100}, jpeg.size() / 2, jpeg.size() - 10}) fails(jpeg, keep, "JPEG");
  fails(progressive, progressive.size() / 2, "JPEG");
  // A flipped byte in the middle of a JPEG's entropy data: libjpeg would go on with a
  // warning; here it is the file's damage.
  size_t scan = 0;  // the entropy data's start: after the start-of-scan marker
  for (size_t i = 0; i + 1 < jpeg.size() && !scan; ++i)
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xDA) scan = i + 2;
  REQUIRE(scan > 0);
  const size_t mid = scan + (jpeg.size() - scan) / 2;
  Bytes flipped = jpeg;
  for (size_t i = mid; i < mid + 8; ++i) flipped[i] = 0xFF;
  flipped[mid + 8] = 0xD0;  // a stray restart marker
  CHECK_THROWS_WITH(decode_image(flipped.data(), flipped.size(), "flipped"), Catch::Contains("truncated or corrupt JPEG"));
  // A PNG's pixel data with a wrong checksum.
  Bytes bad_crc = png;
  bad_crc[png.size() / 2] ^= 0x55;
  CHECK_THROWS_AS(decode_image(bad_crc.data(), bad_crc.size(), "crc"), UserError);
  // The whole file still reads after all.
  CHECK(decoded(png).size() == 64u * 64u * 3u);
  CHECK(decoded(jpeg).size() == 64u * 64u * 3u);
}

TEST_CASE("a PNG whose header claims more pixels than allowed is refused before decoding", "[image][codec][bad-input]") {
  Bytes png = make_png(16, 16, PNG_COLOR_TYPE_RGB, 8, false, false);
  // IHDR's width and height at bytes 16..23: 60000 x 60000, its CRC made right again, so
  // only the limit can refuse it.
  const uint8_t dims[8] = {0, 0, 0xEA, 0x60, 0, 0, 0xEA, 0x60};
  for (size_t i = 0; i < 8; ++i) png[16 + i] = dims[i];
  const uLong crc = crc32(0, png.data() + 12, 17);  // the chunk's type and data
  for (size_t i = 0; i < 4; ++i) png[29 + i] = static_cast<uint8_t>(crc >> (24 - 8 * i));
  CHECK_THROWS_WITH(decode_image(png.data(), png.size(), "huge"), Catch::Contains("3600000000 pixels"));
}

namespace {
// An APP1 EXIF segment holding only the Orientation tag, in either byte order.
Bytes exif_orientation(int v, bool big_endian) {
  Bytes e = {'E', 'x', 'i', 'f', 0, 0};
  auto u16 = [&](unsigned x) {
    if (big_endian) e.insert(e.end(), {uint8_t(x >> 8), uint8_t(x)});
    else e.insert(e.end(), {uint8_t(x), uint8_t(x >> 8)});
  };
  auto u32 = [&](uint32_t x) {
    u16(big_endian ? x >> 16 : x & 0xFFFF);
    u16(big_endian ? x & 0xFFFF : x >> 16);
  };
  e.push_back(big_endian ? 'M' : 'I');
  e.push_back(big_endian ? 'M' : 'I');
  u16(42);
  u32(8);  // the first directory right after the header
  u16(1);  // one entry
  u16(0x0112), u16(3), u32(1), u16(static_cast<unsigned>(v)), u16(0);
  u32(0);  // no next directory
  return e;
}
}  // namespace

TEST_CASE("a JPEG is turned upright as its EXIF Orientation says, in all eight ways", "[image][codec]") {
  // Stored 32 x 16 in quadrants: top-left red, top-right green, bottom-left blue, bottom-right white.
  const int w = 32, h = 16;
  const uint8_t colours[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}};
  Bytes rgb(static_cast<size_t>(w * h * 3));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) rgb[static_cast<size_t>((y * w + x) * 3 + c)] = colours[(y >= h / 2) * 2 + (x >= w / 2)][c];
  // Where each stored quadrant (TL, TR, BL, BR) shows, as (column, row) of the viewed 2 x 2.
  const int shows[9][4][2] = {{},
                              {{0, 0}, {1, 0}, {0, 1}, {1, 1}},   // 1 as stored
                              {{1, 0}, {0, 0}, {1, 1}, {0, 1}},   // 2 mirrored
                              {{1, 1}, {0, 1}, {1, 0}, {0, 0}},   // 3 upside down
                              {{0, 1}, {1, 1}, {0, 0}, {1, 0}},   // 4 mirrored upside down
                              {{0, 0}, {0, 1}, {1, 0}, {1, 1}},   // 5 transposed
                              {{1, 0}, {1, 1}, {0, 0}, {0, 1}},   // 6 turned right
                              {{1, 1}, {1, 0}, {0, 1}, {0, 0}},   // 7 transversed
                              {{0, 1}, {0, 0}, {1, 1}, {1, 0}}};  // 8 turned left
  for (int v = 1; v <= 8; ++v)
    for (bool big_endian : {false, true}) {
      CAPTURE(v, big_endian);
      const Bytes file = encode_jpeg(rgb, w, h, 3, 95, false, exif_orientation(v, big_endian));
      const Image im = decode_image(file.data(), file.size(), "exif");
      const bool swaps = v >= 5;
      REQUIRE(im.width == (swaps ? h : w));
      REQUIRE(im.height == (swaps ? w : h));
      for (int q = 0; q < 4; ++q) {
        const int cx = shows[v][q][0], cy = shows[v][q][1];
        const int x = cx * im.width / 2 + im.width / 4, y = cy * im.height / 2 + im.height / 4;
        for (int c = 0; c < 3; ++c) CHECK(std::abs(int(im.channel(x, y, c)) - int(colours[q][c])) <= 12);
      }
    }
  // A value outside 1-8 and a segment that is not EXIF leave the photo as stored.
  for (const Bytes& odd : {exif_orientation(9, false), Bytes{'h', 't', 't', 'p', ':', '/', '/', 0}}) {
    const Bytes file = encode_jpeg(rgb, w, h, 3, 95, false, odd);
    const Image im = decode_image(file.data(), file.size(), "odd");
    CHECK((im.width == w && im.height == h));
  }
}
