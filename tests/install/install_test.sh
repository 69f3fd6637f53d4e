#!/usr/bin/env bash
# What a user installs: `cmake --install BUILD --prefix P` puts every file where it belongs,
# the man pages render, the installed program runs away from the checkout and finds its
# palettes and profiles by name; `cpack -G DEB` makes a package whose Depends name
# Debian's libraries, and the program extracted from it (dpkg-deb -x) draws.
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "install test: $*" >&2; exit 1; }
t0=$SECONDS

# ---- cmake --install into a temporary prefix ----
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "cmake --install failed"; }
commands=$("$build/src/cli/stipplot" --help | sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && NF {print $1}')
[ -n "$commands" ] || fail "no commands in stipplot --help"
expect=(bin/stipplot share/man/man1/stipplot.1
  share/bash-completion/completions/stipplot share/zsh/site-functions/_stipplot
  share/fish/vendor_completions.d/stipplot.fish)
for c in $commands; do expect+=("share/man/man1/stipplot-$c.1"); done
for p in "$src"/examples/pens/*.toml; do expect+=("share/stipplot/pens/${p##*/}"); done
for p in "$src"/drivers/profiles/*.toml; do expect+=("share/stipplot/profiles/${p##*/}"); done
for f in "${expect[@]}"; do [ -s "$prefix/$f" ] || fail "missing after cmake --install: $f"; done
[ -x "$prefix/bin/stipplot" ] || fail "bin/stipplot is not executable"
[ ! -e "$prefix/share/man/man1/stipplot-help-export.1" ] || fail "the hidden help-export has a man page"
echo "install: ${#expect[@]} files in place"

# ---- the man pages render, without groff warnings ----
for page in "$prefix"/share/man/man1/*.1; do
  out=$(MANWIDTH=100 man --warnings -l "$page" 2>"$work/man.err") || fail "man -l $page failed: $(cat "$work/man.err")"
  [ ! -s "$work/man.err" ] || fail "man -l $page warns: $(cat "$work/man.err")"
  name=$(basename "$page" .1)
  grep -q "^NAME" <<<"$out" || fail "$name: no NAME section rendered"
  grep -q "^ *$name - " <<<"$out" || fail "$name: the NAME line did not render"
done
out=$(MANWIDTH=100 man -l "$prefix/share/man/man1/stipplot-stipple.1")
grep -q -- "--pens" <<<"$out" || fail "stipplot-stipple(1) does not list --pens"
grep -q -- "stipplot-plot(1)" <<<"$out" || fail "stipplot-stipple(1) does not refer to stipplot-plot(1)"
out=$(MANWIDTH=100 man -l "$prefix/share/man/man1/stipplot.1")
grep -q "share/stipplot/pens" <<<"$out" || fail "stipplot(1) does not say where palettes are found"
# man finds them by name in the prefix's manual.
MANPATH=$prefix/share/man man -w stipplot-stipple >/dev/null || fail "man stipplot-stipple: not found in the prefix's MANPATH"
echo "install: $(ls "$prefix"/share/man/man1 | wc -l) man pages render without warnings"

# ---- the installed program, run away from the checkout ----
cp "$src/examples/horse.png" "$work/horse.png"
cd "$work"
bin=$prefix/bin/stipplot
"$bin" --version | grep -q "^stipplot " || fail "installed stipplot --version"
# Profiles and palettes come from PREFIX/share/stipplot, ahead of the source tree's.
"$bin" profiles --json | grep -q "\"file\":\"$prefix/share/stipplot/profiles/grbl-servo.toml\"" ||
  fail "the installed stipplot does not read its profiles from $prefix/share/stipplot/profiles"
printf 'name = "installed only"\n[[pen]]\nname = "installed-pen"\ncolor = "#101010"\n' >"$prefix/share/stipplot/pens/installed-only.toml"
"$bin" hatch horse.png --pens installed-only --time 5min -o hatch.svg --json | grep -q '"pen":"installed-pen"' ||
  fail "the installed stipplot does not find --pens installed-only in $prefix/share/stipplot/pens"
"$bin" stipple horse.png -m color --pens fineliner12 --time 10min -o color.svg -q || fail "--pens fineliner12"
echo "install: the installed program finds palettes and profiles by name ($((SECONDS - t0)) s so far)"

# ---- cpack -G DEB, extracted and run ----
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/pkg" >"$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; fail "cpack -G DEB failed"; }
deb=$(ls "$work"/pkg/*.deb)
depends=$(dpkg-deb -f "$deb" Depends)
echo "install: $(basename "$deb"), Depends: $depends"
for lib in libc6 libstdc++6 libopencv-core406 libopencv-imgproc406 libcairo2 libserialport0 libusb-1.0-0 libtinyxml2-9 libexpat1 libhersheyfont0 hershey-fonts-data zlib1g; do
  grep -q "\b$lib\b" <<<"$depends" || fail "the package's Depends lack $lib: $depends"
done
description=$(dpkg-deb -f "$deb" Description)
[[ $description != *";"* ]] || fail "the package's description has a CMake list separator: $description"
dpkg-deb -c "$deb" >"$work/contents.txt"
for f in usr/bin/stipplot usr/share/man/man1/stipplot.1 usr/share/bash-completion/completions/stipplot \
  usr/share/stipplot/pens/fineliner12.toml usr/share/stipplot/profiles/grbl-servo.toml; do
  grep -q " \./$f\$" "$work/contents.txt" || fail "the package has no /$f"
done
dpkg-deb -x "$deb" "$work/root"
pkg=$work/root/usr/bin/stipplot
"$pkg" --version | grep -q "^stipplot " || fail "the packaged stipplot --version"
"$pkg" stipple horse.png -o x.svg --time 10min --json >stipple.json || fail "the packaged stipplot stipple"
grep -q '"primitives":' stipple.json && [ -s x.svg ] || fail "the packaged stipplot drew nothing: $(cat stipple.json)"
"$pkg" profiles --json | grep -q "\"file\":\"$work/root/usr/share/stipplot/profiles/grbl-servo.toml\"" ||
  fail "the packaged stipplot does not read its own profiles"
echo "install: the packaged program draws ($((SECONDS - t0)) s in all)"
