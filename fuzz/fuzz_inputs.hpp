#pragma once
// One input to each reader a user (or a device file) can feed stipplot, shared by the
// libFuzzer targets (fuzz_main.cpp) and by the replay test that runs the seed corpus and
// every crash input ever found (tests/fuzz/) in the ordinary test suite. A UserError is
// the reader's proper answer to bad input and is swallowed; anything else escapes (a
// bug), and so does every sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace stipplot::fuzz {

struct Target {
  const char* name;  // also the corpus folder: tests/fuzz/corpus/<name>/
  void (*run)(const uint8_t* data, size_t size);
};

// svg (read, then planned when small), gcode, hpgl and ebb (job readers and their segments),
// profile (device TOML), palette (pen TOML), image (the image loader).
const std::vector<Target>& targets();
const Target* find_target(const std::string& name);

}  // namespace stipplot::fuzz
