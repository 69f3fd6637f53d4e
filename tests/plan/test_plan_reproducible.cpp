// The planner's budget is work, not time: the same command gives the same file on a
// quiet machine and on one whose every core is busy.
#include <catch2/catch.hpp>

#include <atomic>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "test_util.hpp"

namespace {

// Spins on every core until destroyed, as a parallel build or `stress --cpu` would.
class BusyCores {
 public:
  BusyCores() {
    const unsigned n = std::max(2u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < n; ++i)
      threads_.emplace_back([this] {
        volatile unsigned long x = 0;
        while (!stop_.load(std::memory_order_relaxed)) x = x + 1;
      });
  }
  ~BusyCores() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

}  // namespace

TEST_CASE("the same command under full CPU load writes byte-identical G-code", "[plan][cli]") {
  test::TempDir dir;
  const std::string img = std::string(STIPPLOT_SOURCE_DIR) + "/examples/coffee.png";
  // ~31k dots at three times the default effort: a few tenths of a second of
  // improvement on a quiet machine, which a time budget would cut at a different point
  // under load (as --optimize-seconds 0.3 does).
  const std::string args = "stipple " + img + " -a 1px -b 4px --optimize-effort 1 --json -o ";
  const auto quiet = test::run_cli(args + dir.file("quiet.gcode"));
  REQUIRE(quiet.exit_code == 0);
  test::RunResult loaded;
  {
    BusyCores busy;
    loaded = test::run_cli(args + dir.file("loaded.gcode"));
  }
  REQUIRE(loaded.exit_code == 0);
  const auto jq = nlohmann::json::parse(quiet.out), jl = nlohmann::json::parse(loaded.out);
  INFO("plan seconds quiet " << jq["seconds_plan"] << ", loaded " << jl["seconds_plan"]);
  CHECK_FALSE(jq["plan_capped"].get<bool>());
  CHECK_FALSE(jl["plan_capped"].get<bool>());
  const std::string a = test::read_file(dir.file("quiet.gcode")), b = test::read_file(dir.file("loaded.gcode"));
  CHECK(a.size() > 100000);
  CHECK(a == b);
}
