#pragma once
// How many threads the parallel parts of stipplot use. They are OpenMP loops (GCC's libgomp,
// part of the compiler, so no package of its own; oneTBB's task scheduler buys nothing for
// loops over fixed blocks). Every parallel part splits its work into blocks that do not
// depend on the thread count and combines them in a fixed order, so a result is the same
// bit for bit whatever the count. Without OpenMP (a compiler that lacks it) they run on one.
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

}  // namespace stipplot
