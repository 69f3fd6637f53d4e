#!/usr/bin/env bash
# The whole test suite again under AddressSanitizer + UndefinedBehaviorSanitizer (GCC,
# -O1 -g1), without the tests that time the host ([realtime], the README outputs, the
# browser run: under a sanitizer they measure the sanitizer). About 15
# minutes on 2 cores, so CI (scripts/test.sh) runs the sanitizers on the fuzz targets
# only; run this before a release or after touching memory-heavy code.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh build-asan -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" -DSTIPPLOT_WERROR=ON \
  -DSTIPPLOT_SANITIZE=ON -DSTIPPLOT_BENCH=OFF
cd build-asan
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j "$(nproc)"
