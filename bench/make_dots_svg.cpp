// Writes n uniform random dots (0.3 mm, the benchmarks' instance) as an SVG, for timing
// whole `stipplot export` commands, and prints the weight of their Euclidean MST, the
// yardstick of pen-up travel: make_dots_svg OUT.svg N [SIDE_MM] [SEED]
#include <cstdio>
#include <cstdlib>

#include "spatial/mst.hpp"
#include "svg/svg_writer.hpp"
#include "synthetic.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: make_dots_svg OUT.svg N [SIDE_MM] [SEED]\n");
    return 2;
  }
  const long n = std::atol(argv[2]);
  const double side = argc > 3 ? std::atof(argv[3]) : 200;
  const unsigned long seed = argc > 4 ? std::strtoul(argv[4], nullptr, 10) : 42;
  if (n <= 0 || !(side > 0 && side <= 400)) {
    std::fprintf(stderr, "make_dots_svg: N must be positive and SIDE_MM in (0, 400]\n");
    return 2;
  }
  const auto pts = stipplot::bench::uniform_dots(static_cast<size_t>(n), side, seed);
  stipplot::Drawing d;
  d.page = {side, side};
  d.layers.resize(1);
  for (const auto& p : pts) d.layers[0].dots.push_back({p, 0.3});
  stipplot::SvgOptions so;
  so.paper_background = false;
  stipplot::write_svg(d, argv[1], so);
  std::printf("{\"dots\":%ld,\"side_mm\":%g,\"seed\":%lu,\"emst_mm\":%.3f}\n", n, side, seed,
              stipplot::spatial::total_cost(stipplot::spatial::euclidean_mst(pts)));
  return 0;
}
