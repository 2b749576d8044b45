#!/bin/sh
# Install the Debian packages a make target needs, when they are missing.
# usage: scripts/deps.sh GROUP...   (groups: build test python bench plot fuzz extras)
# Runs apt-get only as root and only for packages not yet installed; as
# another user it prints the command to run instead.
set -e
pkgs=""
for group in "$@"; do
  case "$group" in
    build)  pkgs="$pkgs gcc make cmake pkg-config libc6-dev" ;;
    extras) pkgs="$pkgs libpng-dev libnifti2-dev zlib1g-dev" ;;
    test)   pkgs="$pkgs python3 locales" ;;
    python) pkgs="$pkgs python3 python3-dev python3-numpy python3-setuptools python3-pytest python3-scipy" ;;
    bench)  pkgs="$pkgs libnanoflann-dev libpcl-dev python3-scipy python3-numpy python3-open3d g++ libomp-dev" ;;
    plot)   pkgs="$pkgs python3-matplotlib python3-numpy" ;;
    fuzz)   pkgs="$pkgs clang libclang-rt-14-dev make libnifti2-dev zlib1g-dev" ;;
    *) echo "deps.sh: unknown group $group" >&2; exit 1 ;;
  esac
done
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" != 0 ]; then
  echo "Missing Debian packages:$missing" >&2
  echo "Install them with: sudo apt-get install$missing" >&2
  exit 1
fi
echo "Installing Debian packages:$missing"
export DEBIAN_FRONTEND=noninteractive
# Try with the package lists as they are; a fresh machine has none, so on
# failure refresh them once and try again.
if ! apt-get install -y -q --no-install-recommends $missing; then
  apt-get update -q
  apt-get install -y -q --no-install-recommends $missing
fi
