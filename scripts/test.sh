#!/usr/bin/env bash
# Set-up plus the whole test suite: a Release build with warnings as errors and every
# test of it, then every reader fuzzed under AddressSanitizer + UndefinedBehaviorSanitizer
# (scripts/fuzz.sh, FUZZ_SECONDS a target). The packages only the tests need install while
# the build runs. scripts/sanitize.sh runs the whole suite under the sanitizers as well; it
# doubles the time, so CI leaves it out.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
phase() { echo "test.sh: $1 done at $((SECONDS - start)) s"; }
bash scripts/setup.sh build
phase "set-up for the build"
mkdir -p build
bash scripts/setup.sh test > build/setup-test.log 2>&1 &
setup_test=$!
bash scripts/build.sh build -DCMAKE_BUILD_TYPE=Release -DSTIPPLOT_WERROR=ON
bash scripts/install_link.sh build
phase "Release build"
if ! wait "$setup_test"; then
  cat build/setup-test.log >&2
  echo "test.sh: installing the tests' packages failed" >&2
  exit 1
fi
cat build/setup-test.log
phase "set-up for the tests"
(cd build && ctest --output-on-failure -j "$(nproc)" -LE 'firmware|ebb')
phase "tests"
# The EiBotBoard firmware v3.0.2 compiled for the PC (ebb_sim, tests/ebb): built into the
# build tree by the first test that needs it, then AxiDraw jobs streamed to it.
(cd build && ctest --output-on-failure -j "$(nproc)" -L ebb)
phase "EBB firmware tests"
# The real grbl 1.1h AVR binary on simavr (tests/firmware): one simulated CPU, paced to the
# wall clock, no host threads to race. A firmware test passes first time or fails.
(cd build && ctest --output-on-failure -L firmware)
phase "firmware tests"
bash scripts/fuzz.sh
phase "fuzzing"
