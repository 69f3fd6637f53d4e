// --threads 0 means one thread per core, or OMP_NUM_THREADS when the user set it (CI runs
// its tests several at a time with OMP_NUM_THREADS=1).
#include <catch2/catch.hpp>

#include <cstdlib>
#include <mutex>
#include <set>
#include <opencv2/core/utility.hpp>
#include <thread>

#include "util/error.hpp"
#include "util/threads.hpp"

using namespace stipplot;

TEST_CASE("thread count: 0 follows OMP_NUM_THREADS when set, else one per core, and a count given wins", "[threads]") {
  const char* before = std::getenv("OMP_NUM_THREADS");
  const std::string saved = before ? before : "";
  ::setenv("OMP_NUM_THREADS", "3", 1);
  set_thread_count(0);
  CHECK(thread_count() == 3);
  set_thread_count(2);
  CHECK(thread_count() == 2);
  ::unsetenv("OMP_NUM_THREADS");
  set_thread_count(0);
  CHECK(thread_count() == static_cast<int>(std::thread::hardware_concurrency()));
  CHECK_THROWS_AS(set_thread_count(-1), UserError);
  CHECK_THROWS_AS(set_thread_count(1025), UserError);
  if (before) ::setenv("OMP_NUM_THREADS", saved.c_str(), 1);
  set_thread_count(0);
}

TEST_CASE("OpenCV's own thread pool takes the count: with one thread its loops run on the caller's", "[threads]") {
  auto threads_used = [] {
    std::mutex m;
    std::set<std::thread::id> ids;
    cv::parallel_for_(cv::Range(0, 64), [&](const cv::Range&) {
      volatile double x = 0;
      for (int i = 0; i < 200000; ++i) x = x + i;  // enough work for a pool to share it out
      std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
    return ids;
  };
  set_thread_count(1);
  CHECK(threads_used() == std::set<std::thread::id>{std::this_thread::get_id()});
  set_thread_count(2);
  CHECK(cv::getNumThreads() == 2);
  CHECK(threads_used().size() <= 2);
  set_thread_count(0);
}
