#!/usr/bin/env bash
# Puts the built stipplot where the README's examples find it: a link in /usr/local/bin
# (as root, or with sudo), else in ~/.local/bin. Usage: install_link.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="$PWD/${1:-build}/src/cli/stipplot"
[ -x "$bin" ] || { echo "install_link: $bin is not built" >&2; exit 1; }
if [ "$(id -u)" -eq 0 ]; then
  dest=/usr/local/bin
elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
  dest=/usr/local/bin
  sudo ln -sf "$bin" "$dest/stipplot" && echo "stipplot: $dest/stipplot -> $bin" && exit 0
else
  dest="$HOME/.local/bin"
  mkdir -p "$dest"
fi
ln -sf "$bin" "$dest/stipplot"
echo "stipplot: $dest/stipplot -> $bin"
