#include "util/threads.hpp"

#include <algorithm>
#include <cstdlib>
#include <opencv2/core/utility.hpp>

#include "util/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace stipplot {

// More threads than any machine has cores would only fail to start (libgomp crashed at 100000).
constexpr int kMostThreads = 1024;

void set_thread_count(int n) {
  require_range("--threads (0: one per core)", n, 0, kMostThreads);
#ifdef _OPENMP
  // 0 is an OMP_NUM_THREADS the user set (its first number), else one per core.
  if (n == 0)
    if (const char* env = std::getenv("OMP_NUM_THREADS"); env && std::atoi(env) > 0) n = std::min(std::atoi(env), kMostThreads);
  omp_set_num_threads(n == 0 ? omp_get_num_procs() : n);
#endif
  // OpenCV's resizes and blurs run on a pool of their own, one thread a core unless told:
  // --threads 1 must be one thread there too. 0 is OpenCV's "no threads": an arena of one
  // would cap its TBB pool at one worker for the rest of the process (a later count of 2
  // ignored, with a warning).
  // At most one a core there: OpenCV's TBB pool refuses more, with a warning on stderr.
  int count = thread_count();
#ifdef _OPENMP
  count = std::min(count, omp_get_num_procs());
#endif
  cv::setNumThreads(count > 1 ? count : 0);
}

int thread_count() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

bool in_parallel_part() {
#ifdef _OPENMP
  return omp_in_parallel() != 0;
#else
  return false;
#endif
}

}  // namespace stipplot
