#include "image/image.hpp"

#include <stb_image.h>

#include <cstdio>
#include <filesystem>
#include <memory>

#include "util/error.hpp"

namespace stipplot {

std::vector<uint8_t> Image::plane(int c) const {
  std::vector<uint8_t> out(pixels());
  for (size_t i = 0; i < out.size(); ++i) out[i] = rgb[i * 3 + static_cast<size_t>(c)];
  return out;
}

std::vector<uint8_t> Image::luma() const {
  std::vector<uint8_t> out(pixels());
  for (size_t i = 0; i < out.size(); ++i) out[i] = luma601(rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]);
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

Image load_image(const std::string& path, const LoadOptions& opt) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw UserError(path + ": no such file");
  if (fs::is_directory(path, ec)) throw UserError(path + ": is a directory, not an image");
  auto size = fs::file_size(path, ec);
  if (ec) throw UserError(path + ": cannot read: " + ec.message());
  if (size == 0) throw UserError(path + ": file is empty");

  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw UserError(path + ": cannot open for reading");
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_file(f.get(), &w, &h, &comp))
    throw UserError(path + ": not a readable image (" + stbi_failure_reason() + ")");
  if (w <= 0 || h <= 0) throw UserError(path + ": image has zero size");
  uint64_t px = static_cast<uint64_t>(w) * static_cast<uint64_t>(h);
  if (px > opt.max_pixels)
    throw UserError(path + ": image is " + std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(px) +
                    " pixels, more than the limit of " + std::to_string(opt.max_pixels) + " (raise it with --max-pixels)");

  std::fseek(f.get(), 0, SEEK_SET);
  unsigned char* data = stbi_load_from_file(f.get(), &w, &h, &comp, 4);
  if (!data) {
    std::string why = stbi_failure_reason() ? stbi_failure_reason() : "";
    throw UserError(path + ": truncated or corrupt image" + (why.empty() ? std::string() : " (decoder: " + why + ")"));
  }
  std::unique_ptr<unsigned char, void (*)(void*)> guard(data, &stbi_image_free);

  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(static_cast<size_t>(px) * 3);
  for (size_t i = 0; i < px; ++i) {
    const unsigned char* p = data + i * 4;
    unsigned a = p[3];
    for (int c = 0; c < 3; ++c)  // composite on white: c*a + 255*(1-a)
      im.rgb[i * 3 + static_cast<size_t>(c)] = static_cast<uint8_t>((p[c] * a + 255u * (255u - a) + 127u) / 255u);
  }
  return im;
}

}  // namespace stipplot
