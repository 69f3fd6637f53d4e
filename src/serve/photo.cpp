#include "serve/photo.hpp"

#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "image/image.hpp"
#include "preview/preview.hpp"
#include "serve/settings.hpp"
#include "util/error.hpp"

namespace stipplot::serve {

namespace fs = std::filesystem;

nlohmann::json Photo::to_json() const {
  return {{"name", name},   {"original_name", original_name}, {"width", width},
          {"height", height}, {"draft", {draft_width, draft_height}}};
}

namespace {

// The extension the first bytes prove, or "" (TGA has no signature: not taken).
std::string sniff_extension(const std::string& b) {
  auto starts = [&](const char* sig, size_t n) { return b.size() >= n && b.compare(0, n, sig, n) == 0; };
  if (starts("\x89PNG\r\n\x1a\n", 8)) return ".png";
  if (starts("\xff\xd8\xff", 3)) return ".jpg";
  if (starts("BM", 2)) return ".bmp";
  return "";
}

Image reduced(const Image& im, uint64_t max_pixels) {
  if (im.pixels() <= max_pixels) return im;
  const double f = std::sqrt(static_cast<double>(max_pixels) / static_cast<double>(im.pixels()));
  const int w = std::max(1, static_cast<int>(im.width * f)), h = std::max(1, static_cast<int>(im.height * f));
  cv::Mat src(im.height, im.width, CV_8UC3, const_cast<uint8_t*>(im.rgb.data()));
  Image out;
  out.width = w;
  out.height = h;
  out.rgb.resize(static_cast<size_t>(w) * h * 3);
  cv::Mat dst(h, w, CV_8UC3, out.rgb.data());
  cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);  // area averaging keeps the tones
  return out;
}

}  // namespace

Photo accept_photo(const std::string& bytes, const fs::path& workdir, uint64_t max_pixels, uint64_t draft_pixels) {
  const std::string ext = sniff_extension(bytes);
  if (ext.empty()) throw RequestError(415, "the upload is not an image (PNG, JPEG or BMP)");
  const fs::path tmp = workdir / ("upload" + ext);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw RequestError(500, "cannot write the upload into the working folder");
  }
  Image im;
  try {
    LoadOptions lo;
    lo.max_pixels = max_pixels;
    im = load_image(tmp.string(), lo);
  } catch (const UserError& e) {
    fs::remove(tmp);
    const std::string why = e.what();
    // The CLI's own sentence, with the upload's name for the server's file name.
    const size_t colon = why.find(':');
    const std::string msg = colon == std::string::npos ? why : "photo" + why.substr(colon);
    throw RequestError(why.find("more than the limit") != std::string::npos ? 413 : 415, msg);
  }
  Photo p;
  p.name = "photo" + ext;
  fs::rename(tmp, workdir / p.name);
  p.width = im.width;
  p.height = im.height;
  const Image d = reduced(im, draft_pixels);
  p.draft_name = "photo-draft.tga";  // read by every draft: an uncompressed TGA reads 10x faster than a PNG
  write_tga(d, (workdir / p.draft_name).string());
  p.draft_width = d.width;
  p.draft_height = d.height;
  return p;
}

}  // namespace stipplot::serve
