#!/usr/bin/env bash
# Configures and builds into $1 (default build/) with extra CMake arguments after it;
# every target, or only those in $STIPPLOT_TARGETS ("stipplot": the program alone).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-build}
shift || true
gen=()
command -v ninja >/dev/null && gen=(-G Ninja)
# Benchmarks in `all` unless the caller says otherwise (scripts/test.sh builds them last).
cmake -S . -B "$dir" "${gen[@]}" -DSTIPPLOT_BENCH_IN_ALL=ON "$@" >/dev/null
targets=()
for t in ${STIPPLOT_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$dir" -j "$(nproc)" "${targets[@]}"
