#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install, build, stipple the bundled sample
# photo, plan it for the generic grbl pen plotter and plot it on the built-in simulated
# plotter. Everything lands in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh build
# The program alone: not the tests and benchmarks the demo does not run.
STIPPLOT_TARGETS=stipplot bash scripts/build.sh build
bash scripts/install_link.sh build
mkdir -p out
S=./build/src/cli/stipplot
# The defaults: A4, a 0.3 mm pen, the tone law, a plot of about an hour on grbl-servo.
$S stipple examples/horse.png -o out/horse.svg --preview out/horse.png --landscape
$S stipple examples/horse.png -o out/horse.gcode --landscape --profile grbl-servo
# The hour's plot at 100x: about 40 s on the simulator.
$S plot out/horse.gcode --profile grbl-servo --sim --sim-speedup 100 --sim-out out/horse-plotted
echo "demo: out/horse.svg (drawing), out/horse.png (preview), out/horse.gcode (job),"
echo "      out/horse-plotted.png/.svg (what the simulated plotter drew)"
