#!/usr/bin/env bash
# Regenerates docs/reference/ (a page per command) from the built program's own option
# definitions: `stipplot help-export --format md`. The test "docs/reference is what the
# program's options say" fails until this has been run after an option changed.
#   gen_docs.sh [BUILD_DIR]   (default build/; the program is built there if needed)
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-build}
if [ -f "$dir/CMakeCache.txt" ]; then
  cmake --build "$dir" --target stipplot >/dev/null
else
  STIPPLOT_TARGETS=stipplot bash scripts/build.sh "$dir"
fi
rm -f docs/reference/*.md
"$dir/src/cli/stipplot" help-export --format md docs/reference
echo "gen_docs: $(ls docs/reference/*.md | wc -l) pages in docs/reference/"
