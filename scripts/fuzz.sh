#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with Debian's clang-14 under AddressSanitizer and
# UndefinedBehaviorSanitizer (float-cast-overflow included) and runs each for
# FUZZ_SECONDS (default 10; seven targets, 40 s on two cores) from its seed corpus,
# tests/fuzz/corpus/<target>/ (copied: the tracked seeds stay as they are). Prints each
# target's executions; a crash, leak, timeout or memory blow-up fails the script and
# leaves its input in build-fuzz/crashes/<target>/: copy it to tests/fuzz/crashes/<target>/,
# where the replay test (tests/fuzz/test_fuzz_replay.cpp) keeps it as a regression test.
#   fuzz.sh          build the targets, then run them, $(nproc) at a time
#   fuzz.sh build    only build them (scripts/test.sh does this beside the firmware tests)
#   fuzz.sh run      only run them (built before)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang++-14 >/dev/null || bash scripts/setup.sh test
secs=${FUZZ_SECONDS:-10}
dir=${FUZZ_BUILD_DIR:-build-fuzz}
gen=()
command -v ninja >/dev/null && gen=(-G Ninja)
CC=clang-14 CXX=clang++-14 cmake -S . -B "$dir" "${gen[@]}" -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" \
  -DSTIPPLOT_FUZZ=ON -DSTIPPLOT_BENCH=OFF >/dev/null
stage=${1:-all}
if [ "$stage" != run ]; then
  cmake --build "$dir" -j "$(nproc)" --target fuzz_all
fi
[ "$stage" = build ] && exit 0
# One target: its result line on stdout, exit status 1 on a finding.
fuzz_one() {
  local t=$1 work="$dir/corpus/$1" log="$dir/fuzz_$1.log"
  rm -rf "$work" "$dir/crashes/$t"
  mkdir -p "$work" "$dir/crashes/$t"
  cp tests/fuzz/corpus/"$t"/* "$work"/
  if ! "$dir/fuzz/fuzz_$t" "$work" -max_total_time="$secs" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 \
      -max_len=65536 -artifact_prefix="$dir/crashes/$t/" >"$log" 2>&1; then
    echo "fuzz $t: FAILED, input in $dir/crashes/$t/ ($(ls "$dir/crashes/$t" | head -1)); see $log"
    grep -m3 -E "ERROR|runtime error|SUMMARY" "$log" || true
    return 1
  fi
  local execs corpus
  execs=$(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}')
  corpus=$(ls "$work" | wc -l)
  echo "fuzz $t: $execs executions in ${secs} s, corpus $corpus inputs, 0 crashes"
}
# Each libFuzzer process is single-threaded: run as many at once as there are cores,
# each target for its full FUZZ_SECONDS, results printed in a fixed order.
status=0
targets=(svg gcode hpgl ebb profile palette image)
lanes=$(nproc)
for ((i = 0; i < ${#targets[@]}; i += lanes)); do
  pids=()
  for t in "${targets[@]:i:lanes}"; do
    fuzz_one "$t" >"$dir/fuzz_$t.result" 2>&1 &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || status=1; done
  for t in "${targets[@]:i:lanes}"; do cat "$dir/fuzz_$t.result"; done
done
exit $status
