"""Build the hausdorff extension module.

Two ways to get the library into the extension, both offline:

* standalone (``pip install --no-build-isolation ./python`` or
  ``python3 setup.py build``): the library's C sources in ``../src`` are
  compiled into the extension with the flags the CMake build uses, most
  importantly ``-ffp-contract=off`` (no fused multiply-add, so results stay
  bit-identical to a brute force);
* from a CMake build (what ``make`` does): the environment variable
  ``HAUSDORFF_STATIC_LIB`` names ``libhausdorff.a`` (the ``hausdorff_static``
  target, whose objects are position independent) and only the extension's
  own file is compiled.

Build time needs numpy, setuptools and Python.h (Debian: python3-numpy,
python3-setuptools, python3-dev); run time needs numpy only.
"""
import glob
import os
import re

import numpy
from setuptools import Extension, setup

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
INCLUDE = os.path.join(ROOT, "include")
HEADER = os.path.join(INCLUDE, "hausdorff.h")

if not os.path.exists(HEADER):
    raise SystemExit(
        f"setup.py: {HEADER} not found; build from a checkout of the hausdorff "
        "repository (the module compiles the C library from ../src)")


def version():
    with open(HEADER, encoding="utf-8") as f:
        m = re.search(r'#define HD_VERSION_STRING "([^"]+)"', f.read())
    return m.group(1) if m else "0"


def exactness_flags():
    """The flags exactness depends on, from the file CMake reads too."""
    with open(os.path.join(ROOT, "cmake", "exactness-flags.txt"), encoding="utf-8") as f:
        return [w for line in f if not line.startswith("#") for w in line.split()]


static_lib = os.environ.get("HAUSDORFF_STATIC_LIB")
sources = [os.path.join("hausdorff", "_hausdorff.c"), os.path.join("hausdorff", "_ndim.c"),
           os.path.join("hausdorff", "_masks.c")]
extra_objects = []
depends = [HEADER, os.path.join(HERE, "hausdorff", "_ndim.h"), os.path.join(HERE, "hausdorff", "_masks.h")]
link_args = ["-pthread"]
if static_lib:
    # Link the CMake archive; keep its symbols out of the module's exports.
    extra_objects.append(static_lib)
    depends.append(static_lib)
    link_args.append("-Wl,--exclude-libs,ALL")
else:
    # src/mpi/ is the optional MPI library (cmake/mpi.cmake), not the core
    lib = sorted(f for f in glob.glob(os.path.join(ROOT, "src", "**", "*.c"), recursive=True)
                 if os.sep + "mpi" + os.sep not in os.path.relpath(f, ROOT))
    sources += [os.path.relpath(p, HERE) for p in lib]
    depends += glob.glob(os.path.join(ROOT, "src", "**", "*.h"), recursive=True)

extension = Extension(
    "hausdorff._hausdorff",
    sources=sources,
    include_dirs=[INCLUDE, os.path.join(ROOT, "src"), numpy.get_include()],
    define_macros=[("_POSIX_C_SOURCE", "200809L"), ("_DEFAULT_SOURCE", None)],
    extra_compile_args=["-std=c11", "-O2"] + exactness_flags() + ["-fvisibility=hidden", "-Wall", "-Wextra"],
    extra_objects=extra_objects,
    extra_link_args=link_args,
    libraries=["m"],
    depends=depends,
)

setup(
    version=version(),
    packages=["hausdorff"],
    package_data={"hausdorff": ["*.pyi", "py.typed"]},
    include_package_data=False,
    ext_modules=[extension],
)
