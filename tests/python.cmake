# The Python module (python/): built against hausdorff_static into
# ${CMAKE_BINARY_DIR}/python by the ALL target hausdorff_python, and tested by
# the CTest entries `python` (pytest on python/tests) and `python_scipy`
# (scipy's own directed_hausdorff tests against the module).
#
# Which interpreter: HD_PYTHON if given, else the first of `python3` on PATH
# and /usr/bin/python3 that can build the module (numpy, setuptools and
# Python.h).  Debian's numpy and scipy live under /usr/bin/python3; a pyenv or
# other python3 earlier on PATH usually lacks them and is then skipped.
#
# Not in the sanitizer build: an archive instrumented with ASan cannot be
# loaded into an interpreter that is not, so neither the module nor its test
# exists there.

if(HD_SANITIZE)
  message(STATUS "Python module: not built with HD_SANITIZE (its test is skipped)")
  return()
endif()

set(HD_PYTHON "" CACHE FILEPATH "Python interpreter for the Python module (empty: search)")

set(_hd_py_probe "import os, sysconfig, numpy, setuptools
inc = sysconfig.get_paths()['include']
assert os.path.exists(os.path.join(inc, 'Python.h')), 'no Python.h'
")
set(_hd_py_candidates ${HD_PYTHON})
if(NOT HD_PYTHON)
  unset(_hd_path_python3 CACHE)
  find_program(_hd_path_python3 NAMES python3)
  set(_hd_py_candidates ${_hd_path_python3} /usr/bin/python3)
  unset(_hd_path_python3 CACHE)
endif()
hd_find_python(HD_PYTHON_EXE "${_hd_py_probe}" ${_hd_py_candidates})

if(NOT HD_PYTHON_EXE)
  message(STATUS "Python module: skipped (no interpreter among '${_hd_py_candidates}' has "
                 "numpy, setuptools and Python.h; scripts/deps.sh python installs them)")
  return()
endif()
message(STATUS "Python module: built with ${HD_PYTHON_EXE}")

set(_hd_py_src ${CMAKE_CURRENT_SOURCE_DIR}/python)
set(_hd_py_out ${CMAKE_BINARY_DIR}/python)
set(_hd_py_tmp ${CMAKE_BINARY_DIR}/python-build)
file(GLOB _hd_py_files CONFIGURE_DEPENDS ${_hd_py_src}/hausdorff/*)
add_custom_command(
  OUTPUT ${_hd_py_tmp}/stamp
  COMMAND ${CMAKE_COMMAND} -E make_directory ${_hd_py_tmp}
  COMMAND ${CMAKE_COMMAND} -E env HAUSDORFF_STATIC_LIB=$<TARGET_FILE:hausdorff_static>
          ${HD_PYTHON_EXE} setup.py -q egg_info --egg-base ${_hd_py_tmp}
          build --force --build-base ${_hd_py_tmp} --build-lib ${_hd_py_out}
  COMMAND ${CMAKE_COMMAND} -E touch ${_hd_py_tmp}/stamp
  WORKING_DIRECTORY ${_hd_py_src}
  DEPENDS hausdorff_static ${_hd_py_files} ${_hd_py_src}/setup.py
          ${CMAKE_CURRENT_SOURCE_DIR}/include/hausdorff.h
  COMMENT "Building the Python module into ${_hd_py_out} with ${HD_PYTHON_EXE}"
  VERBATIM)
add_custom_target(hausdorff_python ALL DEPENDS ${_hd_py_tmp}/stamp)

execute_process(COMMAND ${HD_PYTHON_EXE} -c "import pytest"
  RESULT_VARIABLE _hd_rc OUTPUT_QUIET ERROR_QUIET)
if(NOT _hd_rc EQUAL 0)
  message(STATUS "Python tests: skipped (${HD_PYTHON_EXE} has no pytest; scripts/deps.sh python)")
  return()
endif()
# Run from the build directory so that `import hausdorff` finds the built
# module in ${_hd_py_out}, never the source package without its extension.
# HD_CLI: test_summary.py compares the module's figures with the tool's.
set(_hd_py_env "PYTHONPATH=${_hd_py_out};PYTHONDONTWRITEBYTECODE=1"
               "HD_SOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR};HD_CLI=$<TARGET_FILE:hausdorff_cli>")
add_test(NAME python
  COMMAND ${HD_PYTHON_EXE} -m pytest -q -p no:cacheprovider
          --ignore=${_hd_py_src}/tests/test_scipy_suite.py ${_hd_py_src}/tests
  WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
set_tests_properties(python PROPERTIES ENVIRONMENT "${_hd_py_env}" TIMEOUT 900)

# scipy's own test_hausdorff.py against hausdorff.directed (a drop-in for
# directed_hausdorff), its known differences listed as strict expected
# failures in python/tests/test_scipy_suite.py.  Needs scipy with its tests
# (Debian's python3-scipy has them; scripts/deps.sh python installs it).
execute_process(COMMAND ${HD_PYTHON_EXE} -c
  "import pathlib, scipy; assert (pathlib.Path(scipy.__file__).parent / 'spatial/tests/test_hausdorff.py').is_file()"
  RESULT_VARIABLE _hd_rc OUTPUT_QUIET ERROR_QUIET)
if(_hd_rc EQUAL 0)
  add_test(NAME python_scipy
    COMMAND ${HD_PYTHON_EXE} -m pytest -q -rxs -p no:cacheprovider
            ${_hd_py_src}/tests/test_scipy_suite.py
    WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
  set_tests_properties(python_scipy PROPERTIES ENVIRONMENT "${_hd_py_env}" TIMEOUT 300)
else()
  message(STATUS "Python tests: scipy's test_hausdorff.py not run (${HD_PYTHON_EXE} has no scipy "
                 "with its tests; scripts/deps.sh python)")
endif()
