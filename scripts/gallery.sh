#!/usr/bin/env bash
# Regenerates the README's gallery (docs/gallery/*.png): each method and its main variants
# at the defaults (A4, a 0.3 mm pen, a 1 h budget on grbl-servo unless the caption says
# otherwise) on the sample photos in ../shared/images, as the pen-true preview (what the
# pens lay on paper), plus what the simulated plotter drew for one of them. Photos are
# shown beside as thumbnails. Needs the built program and ImageMagick's `convert`
# (apt-get install imagemagick) for the thumbnails and the sheet sizes.
#   bash scripts/gallery.sh [STIPPLOT] [SHARED]      # ~5 min on 2 cores
# Look at every image before committing it.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-build/src/cli/stipplot}")
shared=$(realpath "${2:-../shared}")
# Debian's ImageMagick (/usr/bin/convert; a `convert` earlier on the PATH may be another program).
convert=/usr/bin/convert
[ -x "$convert" ] || { echo "gallery.sh: needs ImageMagick's convert (apt-get install imagemagick)" >&2; exit 1; }
out=docs/gallery
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
img=$shared/images
width=420  # px of every tile: small, the README shows them side by side
# Every drawing's pen-true preview at 100 dpi (a 0.3 mm line is 1.2 px), scaled to a tile:
# the page as seen from arm's length. detail NAME also keeps a 420 x 280 px piece of the
# 100-dpi render (107 x 71 mm) around the page's centre, where the pen's own lines show.
tile() {  # tile NAME: $work/NAME.png -> docs/gallery/NAME.png
  "$convert" "$work/$1.png" -resize "${width}x" -strip -colors 64 "$out/$1.png"
}
detail() {  # detail NAME [DX DY]: a crop shifted DX, DY px from the centre
  "$convert" "$work/$1.png" -gravity center -crop "${width}x280+${2:-0}+${3:-0}" +repage -strip -colors 64 "$out/$1-detail.png"
}
thumb() {  # thumb PHOTO NAME
  "$convert" "$img/$1" -resize "${width}x" -strip "$out/$2.jpg"
}
draw() {  # draw NAME COMMAND ARGS...: stipplot ARGS -o NAME.svg --preview NAME.png
  local name=$1; shift
  echo "gallery: $name: stipplot $*"
  "$bin" "$@" -o "$work/$name.svg" --preview "$work/$name.png" --preview-dpi 100 --quiet
  tile "$name"
}
thumb coffee.png photo-coffee
thumb horse.png photo-horse
thumb rocket.jpg photo-rocket
thumb starry_night.jpg photo-starry
thumb hubble_deep_field.jpg photo-hubble
draw stipple-coffee stipple "$img/coffee.png" --landscape           # 1 h: the connected stipple (TSP art)
detail stipple-coffee
draw stipple-coffee-4h stipple "$img/coffee.png" --landscape --time 4h   # 4 h: dots
detail stipple-coffee-4h
draw stipple-hubble stipple "$img/hubble_deep_field.jpg" -m negative --landscape
draw stipple-starry-cmyk stipple "$img/starry_night.jpg" -m cmyk --landscape
draw tree-coffee tree "$img/coffee.png" --landscape   # 1 h: each tree one loop, two pens wide
detail tree-coffee
draw tree-horse-paper tree "$img/horse.png" --landscape --law linear   # the paper's look: SIBD over the whole page
detail tree-horse-paper
draw sketch-starry sketch "$img/starry_night.jpg" --landscape
draw sketch-starry-4h sketch "$img/starry_night.jpg" --landscape --time 4h   # every stroke fits: the paper's sketch, no ground
draw sketch-rocket-black sketch "$img/rocket.jpg" --landscape --pens examples/pens/black.toml   # one pen: the ground in tone steps
draw pointillism-starry pointillism "$img/starry_night.jpg" --landscape
draw pointillism-coffee-pens pointillism "$img/coffee.png" --landscape --plot-pens   # fineliners: colour fields hatched, dots over them
detail pointillism-coffee-pens
draw hatch-rocket hatch "$img/rocket.jpg"
# What the simulated grbl plotter drew (its own record of pen-down moves), from the same
# G-code a real plotter would get.
echo "gallery: plotted: stipplot plot on the simulator"
"$bin" stipple "$img/coffee.png" -o "$work/plotted.gcode" --profile grbl-servo --quiet
"$bin" plot "$work/plotted.gcode" --sim --sim-speedup 1000 --sim-out "$work/sim" --page A4 --quiet
"$convert" "$work/sim.png" -resize "${width}x" -strip -colors 64 "$out/plotted-coffee.png"
ls -l "$out"
