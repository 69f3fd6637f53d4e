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
# The benchmarks are built beside the tests (below), not before them: nothing tests them.
bash scripts/build.sh build -DCMAKE_BUILD_TYPE=Release -DSTIPPLOT_WERROR=ON -DSTIPPLOT_BENCH_IN_ALL=OFF
bash scripts/install_link.sh build
phase "Release build"
if ! wait "$setup_test"; then
  cat build/setup-test.log >&2
  echo "test.sh: installing the tests' packages failed" >&2
  exit 1
fi
cat build/setup-test.log
phase "set-up for the tests"
# Three lanes at once. The firmware tests (tests/firmware: the real grbl 1.1h AVR binary on
# simavr, paced to the wall clock, one at a time, a test passes first time or fails) need
# under a core and run at normal priority, as a plotter's host does; after them, in the
# same lane, the EBB firmware tests (tests/ebb: the EiBotBoard firmware v3.0.2 compiled for
# the PC, ebb_sim, streaming AxiDraw jobs). The other tests run beside them at nice 10 on
# every core, and ebb_sim (a second or two), the fuzz targets and the benchmarks build at
# nice 19.
# Tests run several at a time: each on one thread (OMP_NUM_THREADS=1, which --threads 0
# follows), or N processes of N OpenMP threads spin-wait for each other's cores (the tests'
# CPU time fell by a third). The tests that compare thread counts set theirs. Not exported:
# nproc follows it too, and the -j below must stay one a core.
fw_log=build/ci-firmware.log
(cd build && OMP_NUM_THREADS=1 ctest --output-on-failure -L firmware && OMP_NUM_THREADS=1 ctest --output-on-failure -L ebb) >"$fw_log" 2>&1 &
firmware=$!
rm -f build/.ci-beside-built
(set +e; (nice -n 19 sh ../shared/validators/ebb/build.sh "$PWD/build/ebb-sim" && nice -n 19 bash scripts/fuzz.sh build) \
  >build/ci-build-beside.log 2>&1; rc=$?; touch build/.ci-beside-built; exit "$rc") &
built_beside=$!
# The Google Benchmark programs (bench/: nothing tests them) build beside, also at nice 19,
# once the fuzz targets are built (the fuzz run waits for those, not for these); the install
# test, which packs the build tree with cpack (a second ninja in the same folder), waits for
# them (label install, run after the other tests).
(while [ ! -e build/.ci-beside-built ]; do sleep 1; done
 nice -n 19 cmake --build build -j "$(nproc)" --target benchmarks) >build/ci-benchmarks.log 2>&1 &
built_bench=$!
status=0
(cd build && OMP_NUM_THREADS=1 nice -n 10 ctest --output-on-failure -j "$(nproc)" -LE 'firmware|ebb|realtime|faults|install') || status=1
phase "tests"
if ! wait "$built_beside"; then
  tail -30 build/ci-build-beside.log >&2
  echo "test.sh: building ebb_sim or the fuzz targets failed" >&2
  status=1
fi
# While the firmware lane runs on (it needs under a core): the fuzz targets, one per
# core, FUZZ_SECONDS (10) each, at nice 10 like the tests before them (at nice 19, beside
# the benchmarks' build, they ran a quarter of their inputs), then the install test
# (label install: cmake --install and cpack, whose own build step must not run beside the
# benchmarks' ninja in build/) at nice 19; the firmware tests keep their CPU whenever
# they want it.
[ "$status" -ne 0 ] || nice -n 10 bash scripts/fuzz.sh run || status=1
if ! wait "$built_bench"; then
  tail -30 build/ci-benchmarks.log >&2
  echo "test.sh: building the benchmarks failed" >&2
  status=1
fi
[ "$status" -eq 0 ] || { wait "$firmware" || true; cat "$fw_log"; exit 1; }
(cd build && OMP_NUM_THREADS=1 nice -n 19 ctest --output-on-failure -L install) || status=1
phase "fuzzing and the install test (beside the firmware lane)"
wait "$firmware" || status=1
cat "$fw_log"
phase "firmware and EBB firmware tests (beside the tests)"
[ "$status" -eq 0 ] || exit 1
# Faults injected into the built-in simulators (label faults) beside the real-time tests
# (label realtime: a simulated plot timed against the wall clock, one at a time, and the EBB
# firmware fed a spiral in real time, which beside the tests at nice 10 once starved), nothing
# else running: the simulators' clocks are the wall clock sped up, and both sleep most of
# their 73 s (the machine 92 % idle with the fault tests alone). With the fuzz build beside
# the fault tests at nice 19, or four of them at a time, a resume redrew 13 dots where one
# is allowed; with the EBB tests beside these two, the real-time ETA missed its 5 %.
(cd build && OMP_NUM_THREADS=1 ctest --output-on-failure -j "$(nproc)" -L faults) >build/ci-faults.log 2>&1 &
faults=$!
(cd build && OMP_NUM_THREADS=1 ctest --output-on-failure -L realtime) || status=1
wait "$faults" || status=1
cat build/ci-faults.log
phase "simulator fault tests and real-time tests (side by side)"
[ "$status" -eq 0 ] || exit 1
