#!/usr/bin/env bash
# Runs a ctest label (default: firmware) RUNS times in a row (default 20) beside BUSY
# busy loops (default 1: "a busy second core" on a 2-core machine), with no retry, and
# prints one line per run and a tally. The figures in README's "Firmware tests under load"
# come from this script:
#   bash scripts/loadloop.sh build 20 firmware      # -> loadloop-firmware.txt in build/
# Every failing run's ctest output is kept in build/loadloop-<label>-<n>.log.
set -uo pipefail
cd "$(dirname "$0")/.."
dir=${1:-build}
runs=${2:-20}
label=${3:-firmware}
busy=${BUSY:-1}
out="$dir/loadloop-$label.txt"
pids=()
for _ in $(seq "$busy"); do
  sha256sum /dev/zero >/dev/null 2>&1 &
  pids+=($!)
done
trap 'kill "${pids[@]}" 2>/dev/null' EXIT
echo "loadloop: ctest -L $label, $runs runs beside $busy busy loop(s), $(nproc) cores, $(date -u +%FT%TZ)" | tee "$out"
pass=0
for n in $(seq "$runs"); do
  t0=$SECONDS
  log="$dir/loadloop-$label-$n.log"
  if (cd "$dir" && ctest --output-on-failure -L "$label") >"$log" 2>&1; then
    pass=$((pass + 1))
    result=pass
    rm -f "$log"
  else
    result="FAIL ($(grep -cE '\*\*\*Failed|\*\*\*Timeout|\*\*\*Exception' "$log") tests; $log)"
  fi
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  echo "run $n: $result in $((SECONDS - t0)) s, load $load" | tee -a "$out"
done
echo "loadloop: $pass/$runs passed" | tee -a "$out"
[ "$pass" -eq "$runs" ]
