#!/usr/bin/env bash
# Runs every `stipplot ...` example in the sh blocks of README.md and the guides in docs/
# (README first, then the guides in the order of DOCS below), in order, in one scratch
# folder, and prints for each the SHA-256 of every file it wrote (and of its stdout for
# commands that print a result rather than write one: profiles). With --check GOLDEN the
# listing must equal GOLDEN byte for byte; with --update GOLDEN it rewrites GOLDEN.
# The README's placeholder inputs are mapped to real files:
#   photo.jpg -> shared/images/coffee.png, text.png -> shared/images/text.png,
#   moon.png -> shared/images/hubble_deep_field.jpg, my-pens.toml -> examples/pens/fineliner12.toml.
# Examples that need hardware (--port, devices, sim, pen) and the server (serve) are skipped; plot --sim runs with
# --sim-speedup 100000 (what the simulator draws does not depend on its clock).
#   readme_examples.sh STIPPLOT_BIN SOURCE_DIR SHARED_DIR [--check FILE | --update FILE]
set -euo pipefail
bin=$(realpath "$1"); src=$(realpath "$2"); shared=$(realpath "$3"); mode=${4:-}; golden=${5:+$(realpath -m "$5")}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cp "$shared/images/coffee.png" "$work/photo.jpg"
cp "$shared/images/text.png" "$work/text.png"
cp "$shared/images/hubble_deep_field.jpg" "$work/moon.png"
cp "$src/examples/pens/fineliner12.toml" "$work/my-pens.toml"
ln -s "$src/examples" "$work/examples"
out="$work/listing.txt"; : > "$out"
cd "$work"
# Lines of ```sh blocks that start with `stipplot `; a trailing `# comment` is dropped.
DOCS=(README.md docs/install.md docs/page-units-budget.md docs/methods.md docs/pens.md docs/profiles.md
      docs/svg-and-planning.md docs/plotting.md docs/bad-input.md docs/studio.md docs/figures.md)
mapfile -t cmds < <(for f in "${DOCS[@]}"; do
  awk '/^```sh/{on=1; next} /^```/{on=0} on && /^stipplot /{sub(/[ ]+#.*$/, ""); print}' "$src/$f"; done)
n=0
for line in "${cmds[@]}"; do
  case "$line" in
    *--port*|"stipplot devices"*|"stipplot sim "*|"stipplot serve"*|"stipplot pen "*) continue ;;
  esac
  n=$((n + 1))
  run=${line//stipplot /\"\$bin\" }
  [[ "$line" == *" plot "*"--sim"* ]] && run="$run --sim-speedup 100000 --quiet"
  touch "$work/.mark"; sleep 0.01
  echo "\$ $line" >> "$out"
  rc=0; stdout=$(eval "$run" 2>"$work/.stderr") || rc=$?
  # A failing example is part of the listing (its status and message), so a change that
  # mends or breaks it shows.
  [[ $rc == 0 ]] || printf '  exit %d: %s\n' "$rc" "$(head -1 "$work/.stderr")" >> "$out"
  if [[ "$line" == "stipplot profiles"* ]]; then
    printf '  stdout %s\n' "$(printf '%s' "$stdout" | sha256sum | cut -c1-64)" >> "$out"
  fi
  find . -maxdepth 1 -type f -newer .mark ! -name '.*' ! -name listing.txt ! -name '*.journal' -printf '%f\n' | LC_ALL=C sort |
    while read -r f; do printf '  %s %s\n' "$(sha256sum "$f" | cut -c1-64)" "$f"; done >> "$out"
done
case "$mode" in
  --update) cp "$out" "$golden"; echo "updated $golden ($n examples)" ;;
  --check)
    if ! diff -u "$golden" "$out"; then
      echo "README examples' outputs differ from $golden (if the change is meant, rerun with --update)" >&2; exit 1
    fi
    echo "README examples: $n commands, outputs identical to $golden" ;;
  *) cat "$out" ;;
esac
