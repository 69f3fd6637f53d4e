#include "image/image.hpp"

#include <stb_image.h>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>
#include <utility>

#include "codec.h"
#include "util/error.hpp"
#include "util/threads.hpp"

namespace stipplot {

PixelBytes::PixelBytes(const PixelBytes& other) { assign(other.begin(), other.end()); }

PixelBytes::PixelBytes(PixelBytes&& other) noexcept : p_(std::exchange(other.p_, nullptr)), n_(std::exchange(other.n_, 0)) {}

PixelBytes& PixelBytes::operator=(const PixelBytes& other) {
  if (this != &other) assign(other.begin(), other.end());
  return *this;
}

PixelBytes& PixelBytes::operator=(PixelBytes&& other) noexcept {
  if (this != &other) {
    std::free(p_);
    p_ = std::exchange(other.p_, nullptr);
    n_ = std::exchange(other.n_, 0);
  }
  return *this;
}

PixelBytes::~PixelBytes() { std::free(p_); }

PixelBytes PixelBytes::adopt(uint8_t* block, size_t n) {
  PixelBytes b;
  b.p_ = block;
  b.n_ = block ? n : 0;
  return b;
}

PixelBytes PixelBytes::for_writing(size_t n) {
  auto* block = static_cast<uint8_t*>(std::malloc(n ? n : 1));
  if (!block) throw std::bad_alloc();
  PixelBytes b = adopt(block, n);
  // One write a page; a huge page (glibc.malloc.hugetlb) is cleared whole at its first.
  constexpr long kPage = 4096;
  const long pages = static_cast<long>((n + kPage - 1) / kPage);
#pragma omp parallel for num_threads(thread_count()) schedule(static) if (pages >= 1024 && !in_parallel_part())
  for (long p = 0; p < pages; ++p) block[static_cast<size_t>(p * kPage)] = 0;
  return b;
}

void PixelBytes::resize(size_t n) {
  if (n == n_) return;
  if (n == 0) {
    std::free(p_);
    p_ = nullptr;
    n_ = 0;
    return;
  }
  auto* q = static_cast<uint8_t*>(std::realloc(p_, n));
  if (!q) throw std::bad_alloc();
  if (n > n_) std::memset(q + n_, 0, n - n_);
  p_ = q;
  n_ = n;
}

void PixelBytes::assign(size_t n, uint8_t v) {
  resize(n);
  if (n) std::memset(p_, v, n);
}

void PixelBytes::assign(const uint8_t* first, const uint8_t* last) {
  const size_t n = static_cast<size_t>(last - first);
  if (n == 0) {
    resize(0);
    return;
  }
  auto* q = static_cast<uint8_t*>(std::malloc(n));  // (first may lie in the old block)
  if (!q) throw std::bad_alloc();
  std::memcpy(q, first, n);
  std::free(p_);
  p_ = q;
  n_ = n;
}

bool PixelBytes::operator==(const PixelBytes& other) const {
  return n_ == other.n_ && (n_ == 0 || std::memcmp(p_, other.p_, n_) == 0);
}

std::vector<uint8_t> Image::plane(int c) const {
  std::vector<uint8_t> out(pixels());
  for (size_t i = 0; i < out.size(); ++i) out[i] = rgb[i * 3 + static_cast<size_t>(c)];
  return out;
}

std::vector<uint8_t> Image::luma() const {
  std::vector<uint8_t> out(pixels());
  // On every thread from a million pixels (each pixel its own: the same bytes).
  const long n = static_cast<long>(out.size());
#pragma omp parallel for num_threads(thread_count()) schedule(static) if (n >= (1L << 20) && !in_parallel_part())
  for (long i = 0; i < n; ++i) {
    const size_t p = static_cast<size_t>(i);
    out[p] = luma601(rgb[p * 3], rgb[p * 3 + 1], rgb[p * 3 + 2]);
  }
  return out;
}

Image Image::from_grey(int w, int h, const std::vector<uint8_t>& grey) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(grey.size() * 3);
  for (size_t i = 0; i < grey.size(); ++i) im.rgb[i * 3] = im.rgb[i * 3 + 1] = im.rgb[i * 3 + 2] = grey[i];
  return im;
}

namespace {

// The format the first bytes announce, so a damaged file is named for what it is (stb
// reports only the last decoder it tried: a truncated JPEG would read "bad png sig").
const char* announced_format(const uint8_t* d, size_t n) {
  auto starts = [&](const char* magic, size_t len) { return n >= len && std::memcmp(d, magic, len) == 0; };
  if (starts("\xFF\xD8\xFF", 3)) return "JPEG";
  if (starts("\x89PNG", 4)) return "PNG";
  if (starts("BM", 2)) return "BMP";
  if (starts("GIF8", 4)) return "GIF";
  return nullptr;
}

// Formats stb_image would try but stipplot does not read: its PNM decoder reads past the
// end of a truncated 16-bit file (found by fuzzing), and none of these is a photo format
// a user needs here.
const char* refused_format(const uint8_t* d, size_t n) {
  auto starts = [&](const char* magic, size_t len) { return n >= len && std::memcmp(d, magic, len) == 0; };
  if (starts("8BPS", 4)) return "PSD";
  if (starts("#?", 2)) return "HDR";
  if (starts("S\x80\xF6\x34", 4)) return "PIC";
  if (n >= 2 && d[0] == 'P' && (d[1] == '5' || d[1] == '6')) return "PNM";
  return nullptr;
}

std::string damaged(const std::string& name, const char* format, const char* why) {
  return name + ": truncated or corrupt " + (format ? std::string(format) + " " : std::string()) + "image" +
         (why && *why ? std::string(" (decoder: ") + why + ")" : std::string());
}

// A PNG's size as its first chunk (IHDR, at a fixed place) declares it, read before libpng
// reads on to the pixels: a file claiming too many is refused as that, whatever follows.
bool png_declared_size(const uint8_t* d, size_t n, uint64_t& w, uint64_t& h) {
  if (n < 24 || std::memcmp(d + 12, "IHDR", 4) != 0) return false;
  auto be32 = [&](size_t at) {
    return (uint64_t{d[at]} << 24) | (uint64_t{d[at + 1]} << 16) | (uint64_t{d[at + 2]} << 8) | uint64_t{d[at + 3]};
  };
  w = be32(16), h = be32(20);
  return true;
}

// The formats read by their own libraries; the rest (BMP, GIF, TGA) by stb_image.
struct Codec {
  const char* format;
  int (*read)(const uint8_t*, size_t, codec_header*, uint8_t*, char*, size_t);  // out NULL: the header only
  // The size the file declares, where it is known before the library's header read (which
  // may fail on what follows it); NULL for none.
  bool (*declared_size)(const uint8_t*, size_t, uint64_t&, uint64_t&);
};

const Codec* codec_for(const uint8_t* d, size_t n) {
  static const Codec png{"PNG", codec_png_read, png_declared_size};
  static const Codec jpeg{"JPEG", codec_jpeg_read, nullptr};
  const char* format = announced_format(d, n);
  if (!format) return nullptr;
  if (std::strcmp(format, "PNG") == 0) return &png;
  if (std::strcmp(format, "JPEG") == 0) return &jpeg;
  return nullptr;
}

std::string too_many_pixels(const std::string& name, uint64_t w, uint64_t h, uint64_t limit) {
  return name + ": image is " + std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(w * h) +
         " pixels, more than the limit of " + std::to_string(limit) + " (raise it with --max-pixels)";
}

// RGBA composited on white: c*a + 255*(1-a), rounded.
PixelBytes on_white(const uint8_t* rgba, size_t px) {
  PixelBytes rgb = PixelBytes::for_writing(px * 3);
  for (size_t i = 0; i < px; ++i) {
    const uint8_t* p = rgba + i * 4;
    const unsigned a = p[3];
    for (size_t c = 0; c < 3; ++c) rgb[i * 3 + c] = static_cast<uint8_t>((p[c] * a + 255u * (255u - a) + 127u) / 255u);
  }
  return rgb;
}

// The stored pixels turned as EXIF's Orientation says a viewer shows them (2-8; 5-8 swap the
// sides). Each output row on its own, on every thread from a million pixels. O(pixels).
Image upright(const Image& stored, int orientation) {
  const size_t W = static_cast<size_t>(stored.width), H = static_cast<size_t>(stored.height);
  const bool swaps = orientation >= 5;
  Image out;
  out.width = swaps ? stored.height : stored.width;
  out.height = swaps ? stored.width : stored.height;
  out.rgb = PixelBytes::for_writing(stored.rgb.size());
  // Each orientation as a walk: the stored pixel of output (dx, dy) is
  // first + dx * step_x + dy * step_y (in pixels), one switch for the whole image.
  const std::ptrdiff_t w = static_cast<std::ptrdiff_t>(W), last_row = static_cast<std::ptrdiff_t>(H - 1) * w;
  std::ptrdiff_t first = 0, step_x = 1, step_y = w;  // 1: as stored
  switch (orientation) {
    case 2: first = w - 1, step_x = -1, step_y = w; break;              // mirrored
    case 3: first = last_row + w - 1, step_x = -1, step_y = -w; break;  // upside down
    case 4: first = last_row, step_x = 1, step_y = -w; break;           // mirrored upside down
    case 5: first = 0, step_x = w, step_y = 1; break;                   // transposed
    case 6: first = last_row, step_x = -w, step_y = 1; break;           // stored turned left: turn right
    case 7: first = last_row + w - 1, step_x = -w, step_y = -1; break;  // transversed
    case 8: first = w - 1, step_x = w, step_y = -1; break;              // stored turned right: turn left
    default: break;
  }
  const long rows = out.height;
  const size_t ow = static_cast<size_t>(out.width);
#pragma omp parallel for num_threads(thread_count()) schedule(static) if (stored.pixels() >= (1u << 20) && !in_parallel_part())
  for (long r = 0; r < rows; ++r) {
    std::ptrdiff_t at = first + r * step_y;
    uint8_t* d = &out.rgb[static_cast<size_t>(r) * ow * 3];
    for (size_t dx = 0; dx < ow; ++dx, at += step_x, d += 3) {
      const uint8_t* s = &stored.rgb[static_cast<size_t>(at) * 3];
      d[0] = s[0], d[1] = s[1], d[2] = s[2];
    }
  }
  return out;
}

}  // namespace

Image decode_image(const uint8_t* bytes, size_t size, const std::string& name, const LoadOptions& opt) {
  if (size == 0) throw UserError(name + ": file is empty");
  if (size > static_cast<size_t>(INT32_MAX)) throw UserError(name + ": file is larger than 2 GB");
  const int len = static_cast<int>(size);
  if (const char* format = refused_format(bytes, size))
    throw UserError(name + ": " + format + " images are not read (use PNG, JPEG, BMP, GIF or TGA)");
  const Codec* codec = codec_for(bytes, size);
  char why[256] = "";
  uint64_t w = 0, h = 0;
  bool alpha = false;  // an image with alpha decodes to RGBA and is composited on white
  if (codec && codec->declared_size && codec->declared_size(bytes, size, w, h) && w * h > opt.max_pixels)
    throw UserError(too_many_pixels(name, w, h, opt.max_pixels));
  codec_header head{};
  if (codec) {
    if (!codec->read(bytes, size, &head, nullptr, why, sizeof why)) throw UserError(damaged(name, codec->format, why));
    w = head.width, h = head.height, alpha = head.alpha != 0;
  } else {
    int iw = 0, ih = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, len, &iw, &ih, &comp)) {
      if (const char* format = announced_format(bytes, size))
        throw UserError(damaged(name, format, stbi_failure_reason()));
      throw UserError(name + ": not a readable image (none of PNG, JPEG, BMP, GIF, TGA)");
    }
    w = static_cast<uint64_t>(std::max(iw, 0)), h = static_cast<uint64_t>(std::max(ih, 0));
    alpha = comp == 2 || comp == 4;
  }
  if (w == 0 || h == 0) throw UserError(name + ": image has zero size");
  const uint64_t px = w * h;
  if (px > opt.max_pixels || w > INT32_MAX || h > INT32_MAX)
    throw UserError(too_many_pixels(name, w, h, opt.max_pixels));
  Image im;
  im.width = static_cast<int>(w);
  im.height = static_cast<int>(h);
  const size_t n = static_cast<size_t>(px);
  if (codec) {
    PixelBytes out = PixelBytes::for_writing(n * (alpha ? 4 : 3));
    if (!codec->read(bytes, size, &head, out.data(), why, sizeof why)) throw UserError(damaged(name, codec->format, why));
    im.rgb = alpha ? on_white(out.data(), n) : std::move(out);
    // (Two returns: `c ? upright(im) : im` would copy im, 36 MB at 12 MP, on one thread.)
    if (head.orientation > 1 && head.orientation <= 8) return upright(im, head.orientation);
    return im;
  }
  int iw = 0, ih = 0, comp = 0;
  unsigned char* data = stbi_load_from_memory(bytes, len, &iw, &ih, &comp, alpha ? 4 : 3);
  if (!data) throw UserError(damaged(name, announced_format(bytes, size), stbi_failure_reason()));
  if (!alpha) {
    // stb_image's block is the image (it allocates with malloc: STBI_MALLOC is not set in
    // Debian's libstb, and stbi_image_free is free).
    im.rgb = PixelBytes::adopt(data, n * 3);
    return im;
  }
  std::unique_ptr<unsigned char, void (*)(void*)> guard(data, &stbi_image_free);
  im.rgb = on_white(data, n);
  return im;
}

Image load_image(const std::string& path, const LoadOptions& opt) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw UserError(path + ": is a directory, not an image");
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) {
    const int err = errno;
    if (err == ENOENT) throw UserError(path + ": no such file");
    throw UserError(path + ": cannot read: " + std::strerror(err));
  }
  // Read in one piece when the size is known (a file), in chunks otherwise (a pipe).
  std::vector<uint8_t> bytes;
  const auto known = fs::file_size(path, ec);
  if (!ec && known > static_cast<uintmax_t>(INT32_MAX)) throw UserError(path + ": file is larger than 2 GB");
  if (!ec) bytes.resize(static_cast<size_t>(known));
  size_t have = std::fread(bytes.data(), 1, bytes.size(), f.get());
  bytes.resize(have);
  uint8_t buf[1 << 16];
  size_t got;
  while (!std::ferror(f.get()) && (got = std::fread(buf, 1, sizeof buf, f.get())) > 0) {
    bytes.insert(bytes.end(), buf, buf + got);
    if (bytes.size() > static_cast<size_t>(INT32_MAX)) throw UserError(path + ": file is larger than 2 GB");
  }
  if (std::ferror(f.get())) throw UserError(path + ": cannot read: " + std::strerror(errno));
  return decode_image(bytes.data(), bytes.size(), path, opt);
}

}  // namespace stipplot
