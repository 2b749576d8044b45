#!/bin/sh
# README's Python install, as a user on Debian 12 runs it (tests/install.cmake):
# a virtual environment that sees Debian's numpy, the module built into it by
# pip from the sources, offline (--no-index: nothing from PyPI), then imported
# from elsewhere and one distance computed.
#
#   python_venv.sh PYTHON SOURCE
#
# Needs python3-venv (ensurepip) and python3-wheel besides the module's own
# build packages: scripts/deps.sh python installs them.  Works on a copy of
# the sources, so that pip's in-tree build leaves the checkout untouched.
set -eu
py=$1; source=$2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/hd-venv.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$py" -c "import ensurepip, venv" 2>/dev/null \
  || fail "$py cannot make a virtual environment with pip (Debian: python3-venv; scripts/deps.sh python)"
"$py" -c "import wheel" 2>/dev/null \
  || fail "$py has no wheel, which pip --no-build-isolation needs (Debian: python3-wheel; scripts/deps.sh python)"

mkdir "$tmp/checkout"
for d in include src cmake python; do cp -R "$source/$d" "$tmp/checkout/$d"; done
rm -rf "$tmp/checkout/python/build" "$tmp/checkout/python"/*.egg-info
cd "$tmp/checkout"
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_CACHE_DIR=1
unset PYTHONPATH PYTHONHOME VIRTUAL_ENV || true

# The commands of README.md and docs/python.md, as written there.
"$py" -m venv --system-site-packages venv || fail "$py -m venv --system-site-packages venv"
venv/bin/pip install -q --no-index --no-build-isolation ./python || fail "venv/bin/pip install --no-index --no-build-isolation ./python"

cd "$tmp"   # not beside the sources: import what pip installed
venv=$tmp/checkout/venv
"$venv/bin/python" - "$venv" <<'PY' || fail "the installed module"
import math, os, sys
import numpy as np
import hausdorff
venv = os.path.realpath(sys.argv[1])
where = os.path.realpath(hausdorff.__file__)
assert where.startswith(venv + os.sep), f"hausdorff imported from {where}, not from {venv}"
a = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
b = np.array([[0, 0, 0.5], [1, 0.25, 0]])
r = hausdorff.hausdorff(a, b)
assert r.distance == math.sqrt(1.25) and (r.ab.i, r.ab.j) == (2, 0), r
print(f"ok: hausdorff {hausdorff.__version__} from {where}: H = {r.distance!r}, A[{r.ab.i}] B[{r.ab.j}]")
PY
