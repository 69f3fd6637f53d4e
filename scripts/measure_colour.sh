#!/usr/bin/env bash
# Mean CIEDE2000 of the blurred preview against the photo (stipplot eval) for the colour
# methods, on the shared photos: BEFORE_BIN (an older stipplot, its own preview) and
# AFTER_BIN at the default --time and at a --time long enough for the full tone.
# Usage: scripts/measure_colour.sh BEFORE_BIN AFTER_BIN SHARED_DIR OUT_DIR
# IMAGES="a.png b.jpg" measures only those of SHARED_DIR/images.
set -euo pipefail
before=$1 after=$2 shared=$3 out=$4
mkdir -p "$out"
modes=("stipple --method color" "stipple --method cmyk" "sketch --space rgb" "sketch --space hsi"
       "pointillism" "pointillism --plot-pens")
de() { "$after" eval "$1" "$2" --json | python3 -c 'import json,sys; print("%.1f" % json.load(sys.stdin)["mean_de00"])'; }
printf '| method | image | before | after, --time 1h | after, full tone |\n|---|---|---|---|---|\n'
for img in ${IMAGES:-coffee.png horse.png rocket.jpg starry_night.jpg}; do
  for mode in "${modes[@]}"; do
    tag=$(echo "$mode" | tr -c 'a-z0-9' '_')
    b=$out/${img%.*}_${tag}_before.png a=$out/${img%.*}_${tag}_1h.png f=$out/${img%.*}_${tag}_full.png
    $before $mode "$shared/images/$img" -q -o "$out/b.svg" --preview "$b"
    $after $mode "$shared/images/$img" -q -o "$out/a.svg" --preview "$a"
    $after $mode "$shared/images/$img" -q -o "$out/f.svg" --preview "$f" --time 1000h
    printf '| %s | %s | %s | %s | %s |\n' "$mode" "$img" "$(de "$shared/images/$img" "$b")" \
      "$(de "$shared/images/$img" "$a")" "$(de "$shared/images/$img" "$f")"
  done
done
