// --threads 0 means one thread per core, or OMP_NUM_THREADS when the user set it (CI runs
// its tests several at a time with OMP_NUM_THREADS=1).
#include <catch2/catch.hpp>

#include <cstdlib>
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

TEST_CASE("OpenCV's own thread pool takes the same count: --threads 1 is one thread", "[threads]") {
  set_thread_count(1);
  CHECK(cv::getNumThreads() == 1);
  set_thread_count(2);
  CHECK(cv::getNumThreads() == 2);
  set_thread_count(0);
  CHECK(cv::getNumThreads() == thread_count());
}
