#!/usr/bin/env bash
# Installs the Debian 12 packages stipplot needs, only those missing. Idempotent.
#   setup.sh build   what building needs (the libraries, compilers, CMake)
#   setup.sh test    what only the tests need: clang-14 for the fuzz targets, chromium and
#                    playwright-core (npm) for the studio's browser test, Inkscape's examples,
#                    the install test's dpkg-dev and man-db, zsh and fish
#   setup.sh         both
set -euo pipefail
what=${1:-all}
BUILD=(
  build-essential cmake ninja-build pkg-config git
  libserialport-dev libusb-1.0-0-dev libtinyxml2-dev libexpat1-dev catch2
  libopencv-core-dev libopencv-imgproc-dev libstb-dev libcairo2-dev libpng-dev libjpeg62-turbo-dev
  libcli11-dev libtomlplusplus-dev libnanoflann-dev libbenchmark-dev nlohmann-json3-dev
  libhersheyfont-dev hershey-fonts-data zlib1g-dev
  libcpp-httplib-dev  # `stipplot serve`
)
TEST=(
  clang-14 libclang-rt-14-dev  # the libFuzzer targets (scripts/fuzz.sh)
  chromium            # not built against: the studio's browser test drives it headless
  inkscape  # not built against: its example drawings (/usr/share/inkscape/examples) are test inputs
  gcc-avr avr-libc binutils-avr simavr libsimavr-dev  # the firmware oracle: grbl 1.1h's AVR binary on simavr
  gcc-multilib  # the EBB oracle: ebb_sim, the EiBotBoard firmware built with gcc -m32 (C18's 32-bit long)
  dpkg-dev file man-db  # the install test: cpack -G DEB's dpkg-shlibdeps (which reads `file`), man -l
  zsh fish  # the generated zsh and fish completions are checked by the shells themselves
)
# The browser test's driver (playwright-core, tests/browser) comes from npm.
command -v npm >/dev/null 2>&1 || TEST+=(nodejs npm)
case $what in
  build) PKGS=("${BUILD[@]}") ;;
  test) PKGS=("${TEST[@]}") ;;
  all) PKGS=("${BUILD[@]}" "${TEST[@]}") ;;
  *) echo "setup.sh: build, test or nothing (both), not '$what'" >&2; exit 2 ;;
esac
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup ($what): all ${#PKGS[@]} packages present"
else
  echo "setup ($what): installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
[ "$what" = build ] && exit 0
# ebb_sim (the EBB oracle) is a 32-bit program. A kernel without 32-bit support (some VMs:
# "Exec format error") runs it through qemu-user's qemu-i386 registered with binfmt_misc
# (the sim re-executes itself on a reboot command, so a plain qemu-i386 prefix would not do).
i386_dir=$(mktemp -d)
echo 'int main(void) { return 0; }' >"$i386_dir/a.c"
if gcc -m32 -o "$i386_dir/a" "$i386_dir/a.c" && ! "$i386_dir/a" 2>/dev/null; then
  echo "setup (test): this kernel runs no 32-bit program; ebb_sim will run under qemu-i386"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  if ! dpkg-query -W -f='${Status}' qemu-user 2>/dev/null | grep -q "install ok installed"; then
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends qemu-user
  fi
  binfmt=/proc/sys/fs/binfmt_misc
  [ -e $binfmt/register ] || $SUDO mount -t binfmt_misc binfmt_misc $binfmt
  if [ ! -e $binfmt/qemu-i386 ]; then
    printf '%s' ':qemu-i386:M::\x7fELF\x01\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x02\x00\x03\x00:\xff\xff\xff\xff\xff\xfe\xfe\x00\xff\xff\xff\xff\xff\xff\xff\xff\xfe\xff\xff\xff:/usr/bin/qemu-i386:' |
      $SUDO tee $binfmt/register >/dev/null
  fi
  "$i386_dir/a" || { echo "setup.sh: 32-bit programs still do not run; the EBB tests need them" >&2; exit 1; }
fi
rm -rf "$i386_dir"
# playwright-core as the lock file pins it (no browser download: it drives /usr/bin/chromium).
browser_dir="$(dirname "$0")/../tests/browser"
if ! cmp -s "$browser_dir/package-lock.json" "$browser_dir/node_modules/.installed-lock.json" 2>/dev/null; then
  (cd "$browser_dir" && npm ci --no-audit --no-fund --loglevel=error && cp package-lock.json node_modules/.installed-lock.json)
fi
