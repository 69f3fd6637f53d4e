// Terrain maps (seed 002, §5 and §6.3): the trees are valleys cut into a height field.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "methods/tree/tree.hpp"

namespace stipplot::tree {

namespace {
struct Rgb {
  double r, g, b;
};
constexpr Rgb kLow{40, 150, 50};    // dark input / near an edge: green lowland
constexpr Rgb kHigh{215, 45, 35};   // bright input / far from edges: red highland
constexpr Rgb kEdge{35, 70, 225};   // major edges (cross variants): blue rivers
}  // namespace

Image terrain(const TreeResult& r, const TerrainParams& p) {
  p.validate();
  const int w = r.width, h = r.height;
  const size_t n = static_cast<size_t>(w) * h;

  // Rasterise every tree (the superpositions cut both) and measure the distance from it.
  std::vector<uint8_t> lines(n, 0);
  cv::Mat canvas(h, w, CV_8U, lines.data());
  for (const TreeLayer& layer : r.layers)
    for (const Edge& e : layer.edges)
      cv::line(canvas, cv::Point(int(r.points.x[e.a]), int(r.points.y[e.a])),
               cv::Point(int(r.points.x[e.b]), int(r.points.y[e.b])), cv::Scalar(255), 1, cv::LINE_8);
  const std::vector<float> valley = distance_from(lines, w, h);

  // Ground: the input's grey (bright = high), or for the cross variants the distance
  // from the major edges scaled to grey levels, so the edges are the river beds.
  std::vector<float> ground(n);
  float gmax = 0;
  for (size_t i = 0; i < n; ++i) {
    ground[i] = r.cross ? r.field[i] : float(r.grey[i]);
    gmax = std::max(gmax, ground[i]);
  }
  // Colour by absolute grey (the paper: white = red, dark = green); the edge distance
  // has no absolute scale, so it is taken relative to its maximum.
  const double to_unit = r.cross ? (gmax > 0 ? 1.0 / gmax : 0) : 1.0 / 255;
  cv::Mat height(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    float* row = height.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      row[x] = float(ground[i] + p.valley_depth * valley[i]);
    }
  }
  // A touch of smoothing so the V of each valley shades as a slope, not pixel noise.
  cv::GaussianBlur(height, height, cv::Size(0, 0), 0.8, 0.8, cv::BORDER_REPLICATE);
  cv::Mat hx, hy;
  cv::Sobel(height, hx, CV_32F, 1, 0, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);
  cv::Sobel(height, hy, CV_32F, 0, 1, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);

  // Bump mapping: Lambert shading of the height field's normals. Azimuth clockwise
  // from up; image y points down.
  const double az = p.azimuth * M_PI / 180, el = p.elevation * M_PI / 180;
  const double lx = std::sin(az) * std::cos(el), ly = -std::cos(az) * std::cos(el), lz = std::sin(el);
  const double k = p.relief / 10;  // slope (grey levels / px) to normal tilt
  Image out;
  out.width = w, out.height = h;
  out.rgb.resize(n * 3);
  for (int y = 0; y < h; ++y) {
    const float* gx = hx.ptr<float>(y);
    const float* gy = hy.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const double nx = -k * gx[x], ny = -k * gy[x];
      const double lambert = std::max(0.0, (nx * lx + ny * ly + lz) / std::sqrt(nx * nx + ny * ny + 1));
      const double shade = 0.3 + 0.7 * lambert / lz;  // flat ground keeps its colour
      const double t = std::clamp(ground[i] * to_unit, 0.0, 1.0);
      Rgb c{kLow.r + t * (kHigh.r - kLow.r), kLow.g + t * (kHigh.g - kLow.g), kLow.b + t * (kHigh.b - kLow.b)};
      if (r.cross && r.edge_mask[i]) c = kEdge;
      out.rgb[i * 3 + 0] = static_cast<uint8_t>(std::clamp(c.r * shade, 0.0, 255.0));
      out.rgb[i * 3 + 1] = static_cast<uint8_t>(std::clamp(c.g * shade, 0.0, 255.0));
      out.rgb[i * 3 + 2] = static_cast<uint8_t>(std::clamp(c.b * shade, 0.0, 255.0));
    }
  }
  return out;
}

}  // namespace stipplot::tree
