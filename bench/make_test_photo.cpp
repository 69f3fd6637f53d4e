// Writes the benchmarks' photo-like synthetic image as a PNG, for timing whole
// commands: make_test_photo OUT.png [WIDTH HEIGHT]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "preview/preview.hpp"
#include "synthetic.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_test_photo OUT.png [WIDTH HEIGHT]\n");
    return 2;
  }
  int w = argc > 3 ? std::atoi(argv[2]) : 3840, h = argc > 3 ? std::atoi(argv[3]) : 2160;
  if (w <= 0 || h <= 0) {
    std::fprintf(stderr, "make_test_photo: bad size\n");
    return 2;
  }
  stipplot::write_png(stipplot::bench::photo_like(w, h), argv[1]);
  return 0;
}
