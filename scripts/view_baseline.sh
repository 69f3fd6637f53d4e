#!/usr/bin/env bash
# The viewing-distance baseline: every method at its defaults (--time 1h on grbl-servo) on
# the shared photos, laid on A4 as ../shared/peers/measure.py expects (297x210mm for a wide
# photo, 210x297mm for a tall one, margin 10), scored by `stipplot eval PHOTO X.svg` at
# sigma 0.5 mm and 1 mm. Prints a Markdown table; the drawings stay in OUT_DIR.
# Usage: scripts/view_baseline.sh STIPPLOT_BIN SHARED_DIR OUT_DIR
# IMAGES="coffee.png" measures only those of SHARED_DIR/images; TIME=4h plans for another
# budget (default 1h); METHODS="stipple --connect;stipple --dots" measures only those
# command lines (';'-separated; each names its rows).
set -euo pipefail
bin=$1 shared=$2 out=$3
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
time_budget=${TIME:-1h}
methods=("stipple" "stipple --connect" "stipple --dots" "stipple --law linear" "tree" "sketch --pens $here/examples/pens/black.toml" "pointillism")
names=("stipple (the budget's choice)" "stipple --connect" "stipple --dots" "stipple --law linear" "tree" "sketch, one black pen" "pointillism")
if [[ -n ${METHODS:-} ]]; then
  IFS=';' read -r -a methods <<< "$METHODS"
  names=("${methods[@]}")
fi
printf '| photo | method | SSIM 0.5 mm | SSIM 1 mm | r 0.5 mm | r 1 mm | tone err 1 mm | plan min | pen lifts |\n'
printf '|---|---|---:|---:|---:|---:|---:|---:|---:|\n'
for img in ${IMAGES:-coffee.png horse.png rocket.jpg}; do
  photo=$shared/images/$img
  for i in "${!methods[@]}"; do
    svg=$out/${img%.*}_${time_budget}_$(echo "${methods[$i]%% /*}" | tr -c 'a-z0-9' '_' | sed 's/_*$//').svg
    # A landscape page first; a tall photo (image_px in the JSON) is drawn again upright.
    # shellcheck disable=SC2086
    nice -n 10 "$bin" ${methods[$i]} "$photo" -o "$svg" --profile grbl-servo --page 297x210mm --margin 10 --time "$time_budget" --json \
      > "$svg.json"
    read -r w h < <(jq -r '"\(.image_px[0]) \(.image_px[1])"' "$svg.json")
    if (( h > w )); then
      # shellcheck disable=SC2086
      nice -n 10 "$bin" ${methods[$i]} "$photo" -o "$svg" --profile grbl-servo --page 210x297mm --margin 10 --time "$time_budget" --json \
        > "$svg.json"
    fi
    minutes=$(jq '.plan.total.seconds / 60' "$svg.json")
    lifts=$(jq '.plan.total.pen_lifts' "$svg.json")
    e05=$(nice -n 10 "$bin" eval "$photo" "$svg" --view-sigma 0.5mm --json)
    e1=$(nice -n 10 "$bin" eval "$photo" "$svg" --view-sigma 1mm --json)
    printf '| %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f | %d |\n' "$img" "${names[$i]}" \
      "$(jq .ssim_view <<< "$e05")" "$(jq .ssim_view <<< "$e1")" "$(jq .tone_r_view <<< "$e05")" \
      "$(jq .tone_r_view <<< "$e1")" "$(jq .tone_err_view <<< "$e1")" "$minutes" "$lifts"
  done
done
