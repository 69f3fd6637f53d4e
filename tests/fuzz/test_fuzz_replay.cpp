// The fuzz targets' seed corpus and every input that ever crashed or ran away, replayed
// through the same entry points in the ordinary test suite (and so under the ASan build):
// each reader answers each input with a result or a UserError, in bounded time.
#include <catch2/catch.hpp>

#include <chrono>
#include <filesystem>

#include "fuzz/fuzz_inputs.hpp"
#include "test_util.hpp"

namespace {
namespace fs = std::filesystem;
const fs::path kFuzzDir = fs::path(STIPPLOT_SOURCE_DIR) / "tests" / "fuzz";

size_t replay(const char* folder) {
  size_t n = 0;
  for (const auto& target : stipplot::fuzz::targets()) {
    const fs::path dir = kFuzzDir / folder / target.name;
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string bytes = test::read_file(e.path().string());
      INFO(target.name << ": " << e.path().filename().string());
      const auto t0 = std::chrono::steady_clock::now();
      CHECK_NOTHROW(target.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
      CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < 20);
      ++n;
    }
  }
  return n;
}
}  // namespace

TEST_CASE("every fuzz target reads its seed corpus", "[fuzz]") {
  for (const auto& target : stipplot::fuzz::targets()) {
    INFO(target.name);
    CHECK(fs::is_directory(kFuzzDir / "corpus" / target.name));
    CHECK(!fs::is_empty(kFuzzDir / "corpus" / target.name));
  }
  CHECK(replay("corpus") >= 20);
}

TEST_CASE("every input that once crashed or ran away is answered", "[fuzz]") {
  CHECK(replay("crashes") >= 7);
}
