#!/bin/sh
# Install the Debian packages a make target needs, when they are missing.
# usage: scripts/deps.sh GROUP...   (groups: build test python bench cgal plot fuzz extras mpi)
# Runs apt-get only as root and only for packages not yet installed, without
# recommends (the minimal set); as another user it prints the same command,
# to run as root, instead.  Each package is named once.
set -e
pkgs=""
add() {
  for p in "$@"; do
    case " $pkgs " in *" $p "*) ;; *) pkgs="$pkgs $p" ;; esac
  done
}
for group in "$@"; do
  case "$group" in
    build)  add gcc make cmake pkg-config libc6-dev ;;
    extras) add libpng-dev libnifti2-dev zlib1g-dev ;;
    # python3-nibabel: tests/cli_nifti_reference.py writes MONAI's and medpy's test masks with it.
    # Not nodejs and npm: the laz-perf cross-check that needs them and the
    # npm registry is an extra that `make test` runs only where they are
    # (tests/laz_lazperf.cmake); nothing in it needs a registry but Debian's.
    test)   add python3 locales python3-nibabel ;;
    # python3-venv and python3-wheel: README's `pip install --no-build-isolation
    # ./python` in a venv (tests/python_venv.sh).
    python) add python3 python3-dev python3-numpy python3-setuptools python3-pytest python3-scipy \
                python3-venv python3-wheel ;;
    bench)  add libnanoflann-dev libpcl-dev python3-scipy python3-numpy python3-open3d g++ libomp-dev libcgal-dev libgmp-dev libmpfr-dev ;;
    # The surface-to-surface benchmark's CGAL peer (bench/peers/m2m_cgal.cpp, header-only).
    cgal)   add g++ libcgal-dev libgmp-dev libmpfr-dev ;;
    plot)   add python3-matplotlib python3-numpy ;;
    # Open MPI: the optional scale-out library and tool (cmake/mpi.cmake), and
    # mpirun for their tests (tests/mpi.cmake).
    mpi)    add libopenmpi-dev openmpi-bin ;;
    fuzz)   add clang libclang-rt-14-dev make libnifti2-dev zlib1g-dev ;;
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
  echo "Install them as root (then run make again):" >&2
  echo "  su -c 'apt-get update && apt-get install -y --no-install-recommends$missing'" >&2
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
