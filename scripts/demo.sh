#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install, build, stipple the bundled
# sample photo, and write the SVG and preview into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh build
mkdir -p out
./build/src/cli/stipplot stipple examples/horse.png -o out/horse.svg --preview out/horse.png --method gray -a 2 -b 8
echo "demo: open out/horse.svg (plotter drawing) and out/horse.png (preview)"
