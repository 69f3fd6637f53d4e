#pragma once
// Images as the methods see them: 8-bit RGB, alpha already composited on white.
#include <cstdint>
#include <string>
#include <vector>

namespace stipplot {

// An image's bytes in one malloc'd block, so that a decoder's own buffer becomes the image
// as it is: a 12-megapixel photo's 36 MB are neither copied nor faulted in twice. The parts
// of a vector's interface the code uses; new bytes read 0, as a vector's do.
class PixelBytes {
 public:
  PixelBytes() = default;
  PixelBytes(const PixelBytes& other);
  PixelBytes(PixelBytes&& other) noexcept;
  PixelBytes& operator=(const PixelBytes& other);
  PixelBytes& operator=(PixelBytes&& other) noexcept;
  ~PixelBytes();
  // Takes a block from malloc (stb_image's result), n bytes long; it is freed with free().
  static PixelBytes adopt(uint8_t* block, size_t n);
  // n bytes of no particular value, for a decoder to fill: their pages are first touched on
  // every thread, since a fresh page's fault and clearing costs about as much as decoding
  // into it (measured: docs/figures.md), and would otherwise fall on the decoder's thread.
  static PixelBytes for_writing(size_t n);  // O(n / page size); throws std::bad_alloc

  uint8_t* data() { return p_; }
  const uint8_t* data() const { return p_; }
  size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  uint8_t& operator[](size_t i) { return p_[i]; }
  const uint8_t& operator[](size_t i) const { return p_[i]; }
  uint8_t* begin() { return p_; }
  uint8_t* end() { return p_ + n_; }
  const uint8_t* begin() const { return p_; }
  const uint8_t* end() const { return p_ + n_; }
  void resize(size_t n);  // O(n); throws std::bad_alloc
  void assign(size_t n, uint8_t v);
  void assign(const uint8_t* first, const uint8_t* last);
  bool operator==(const PixelBytes& other) const;

 private:
  uint8_t* p_ = nullptr;
  size_t n_ = 0;
};

struct Image {
  int width = 0, height = 0;
  PixelBytes rgb;  // row-major, 3 bytes a pixel

  size_t pixels() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
  uint8_t channel(int x, int y, int c) const { return rgb[(static_cast<size_t>(y) * width + x) * 3 + c]; }
  // One channel as a grey plane (0 = R, 1 = G, 2 = B).
  std::vector<uint8_t> plane(int c) const;
  // Rec. 601 luma, the papers' d in 0..255. O(pixels), on every thread from a million.
  std::vector<uint8_t> luma() const;
  static Image from_grey(int w, int h, const std::vector<uint8_t>& grey);
};

struct LoadOptions {
  uint64_t max_pixels = 100'000'000;  // --max-pixels
};

// PNG (libpng), JPEG (libjpeg-turbo), BMP, GIF, TGA (stb_image; its PNM, PSD, HDR and PIC
// decoders are refused). A JPEG is turned upright as its EXIF Orientation says (a phone's
// portrait photo is stored on its side), as every photo viewer shows it. Throws UserError with one line
// naming the file and the problem: missing, empty, not an image, truncated, zero size,
// or more pixels than allowed (checked from the header, before decoding).
Image load_image(const std::string& path, const LoadOptions& opt = {});
// The same from the file's bytes; `name` is used in error messages. O(pixels).
Image decode_image(const uint8_t* bytes, size_t size, const std::string& name, const LoadOptions& opt = {});

// Rec. 601 luma of one RGB triple, rounded.
inline uint8_t luma601(uint8_t r, uint8_t g, uint8_t b) {
  return static_cast<uint8_t>((299u * r + 587u * g + 114u * b + 500u) / 1000u);
}

}  // namespace stipplot
