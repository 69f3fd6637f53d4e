#!/usr/bin/env bash
# Set-up plus the whole test suite: a Release build with warnings as errors, then the
# same tests under AddressSanitizer + UndefinedBehaviorSanitizer, then every reader
# fuzzed for a bounded time (scripts/fuzz.sh, 90 s of fuzzing).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
phase() { echo "test.sh: $1 done at $((SECONDS - start)) s"; }
bash scripts/setup.sh
phase set-up
bash scripts/build.sh build -DCMAKE_BUILD_TYPE=Release -DSTIPPLOT_WERROR=ON
phase "Release build"
(cd build && ctest --output-on-failure -j "$(nproc)")
phase "Release tests"
# -O1 -g1: what the sanitizers recommend, and far quicker to build than -O2 -g.
bash scripts/build.sh build-asan -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" -DSTIPPLOT_WERROR=ON -DSTIPPLOT_SANITIZE=ON -DSTIPPLOT_BENCH=OFF
phase "sanitizer build"
(cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j "$(nproc)")
phase "sanitizer tests"
bash scripts/fuzz.sh
phase fuzzing
