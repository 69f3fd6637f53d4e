// A libFuzzer target for one reader, chosen at compile time (STIPPLOT_FUZZ_TARGET).
#include <cstdlib>

#include "fuzz/fuzz_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const stipplot::fuzz::Target* target = stipplot::fuzz::find_target(STIPPLOT_FUZZ_TARGET);
  if (!target) std::abort();
  target->run(data, size);
  return 0;
}
