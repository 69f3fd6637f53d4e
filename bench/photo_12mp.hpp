#pragma once
// The benchmarks' 12-megapixel photo: examples/coffee.png upscaled to 4243x2828 (3:2),
// written once as a PNG in the temp folder, so whole commands can read it as a file; and
// the same as a JPEG (quality 90, as a camera writes a photo).
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <stb_image_write.h>
#include <stdexcept>
#include <string>

#include "image/image.hpp"
#include "preview/preview.hpp"

namespace stipplot::bench {

inline const std::string& photo_12mp() {
  namespace fs = std::filesystem;
  static const std::string path = [] {
    const std::string out = (fs::temp_directory_path() / "stipplot_bench_coffee_12mp.png").string();
    if (!fs::exists(out)) {
      Image src = load_image((fs::path(__FILE__).parent_path().parent_path() / "examples" / "coffee.png").string());
      Image big;
      big.width = 4243;
      big.height = 2828;  // 12.0 Mpx, 3:2
      big.rgb.resize(big.pixels() * 3);
      cv::Mat s(src.height, src.width, CV_8UC3, src.rgb.data()), d(big.height, big.width, CV_8UC3, big.rgb.data());
      cv::resize(s, d, d.size(), 0, 0, cv::INTER_CUBIC);
      write_png(big, out);
    }
    return out;
  }();
  return path;
}

inline const std::string& photo_12mp_jpeg() {
  namespace fs = std::filesystem;
  static const std::string path = [] {
    const std::string out = (fs::temp_directory_path() / "stipplot_bench_coffee_12mp.jpg").string();
    if (!fs::exists(out)) {
      const Image big = load_image(photo_12mp());
      if (!stbi_write_jpg(out.c_str(), big.width, big.height, 3, big.rgb.data(), 90))
        throw std::runtime_error("cannot write " + out);
    }
    return out;
  }();
  return path;
}

}  // namespace stipplot::bench
