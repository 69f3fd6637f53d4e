#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install, build, stipple the bundled sample
# photo, plan it for the generic grbl pen plotter and plot it on the built-in simulated
# plotter. Everything lands in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh build
mkdir -p out
S=./build/src/cli/stipplot
$S stipple examples/horse.png -o out/horse.svg --preview out/horse.png -a 2 -b 8 --landscape
$S stipple examples/horse.png -o out/horse.gcode -a 2 -b 8 --landscape --profile grbl-servo
$S plot out/horse.gcode --profile grbl-servo --sim --sim-speedup 200 --sim-out out/horse-plotted
echo "demo: out/horse.svg (drawing), out/horse.png (preview), out/horse.gcode (job),"
echo "      out/horse-plotted.png/.svg (what the simulated plotter drew)"
