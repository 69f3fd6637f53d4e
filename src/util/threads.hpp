#pragma once
// How many threads the parallel parts of stipplot use. They are OpenMP loops (GCC's libgomp,
// part of the compiler, so no package of its own; oneTBB's task scheduler buys nothing for
// loops over fixed blocks). Every parallel part splits its work into blocks that do not
// depend on the thread count and combines them in a fixed order, so a result is the same
// bit for bit whatever the count. Without OpenMP (a compiler that lacks it) they run on one.
#include <atomic>
#include <exception>
#include <mutex>

namespace stipplot {

// n threads from now on; 0 = one per core, or OMP_NUM_THREADS when it is set. Below 0 or
// above 1024 is refused.
void set_thread_count(int n);
// The threads a parallel part uses now (1 without OpenMP).
int thread_count();
// True inside a parallel part's threads: a part called from there runs on its caller's thread.
bool in_parallel_part();
// This thread's number in the parallel part it runs in, 0 .. thread_count() - 1 (0 outside one).
int thread_index();

// The first error a parallel loop's iterations throw (an exception must not leave an
// OpenMP region): each iteration runs inside capture(), the rest may skip their work once
// failed(), and rethrow() after the loop throws it on the caller's thread.
class FirstError {
 public:
  template <class F>
  void capture(F&& f) noexcept {
    try {
      f();
    } catch (...) {
      const std::lock_guard<std::mutex> g(m_);
      if (!error_) error_ = std::current_exception();
      failed_ = true;
    }
  }
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex m_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

}  // namespace stipplot
