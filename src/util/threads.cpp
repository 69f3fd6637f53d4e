#include "util/threads.hpp"

#include <string>

#include "util/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace stipplot {

void set_thread_count(int n) {
  if (n < 0) throw UserError("--threads must be 0 (every core) or more, not " + std::to_string(n));
#ifdef _OPENMP
  omp_set_num_threads(n == 0 ? omp_get_num_procs() : n);
#endif
}

int thread_count() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

}  // namespace stipplot
