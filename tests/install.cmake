# Every promised install path, run as a user runs it (issue 18 item 4):
#
#   install        cmake --install into a temporary prefix, then a C program
#                  built with pkg-config (LD_LIBRARY_PATH, rpath, static) and
#                  one with find_package(hausdorff) (shared and static
#                  targets), each run and its answer checked; with MPI,
#                  hausdorff_mpi.h's first program built from the installed
#                  files (its link line, hausdorff_mpi.pc, static,
#                  hausdorff::hausdorff_mpi) and run under mpirun
#                  (tests/install_check.sh prefix);
#   install_make   `make install PREFIX=...` writes a .pc for that prefix and
#                  says what to set, without Entering/Leaving lines; `make
#                  run` builds the tool only (tests/install_check.sh make);
#   install_deps   scripts/deps.sh's message to a non-root user
#                  (tests/install_check.sh deps);
#   make_rules     a failed configure tried again by the next `make run`;
#                  `make test` runs and reports both halves, failing when
#                  either fails (tests/install_check.sh makefile, with
#                  stand-ins for cmake and ctest);
#   python_venv    README's `pip install --no-index --no-build-isolation
#                  ./python` in a --system-site-packages venv, then one
#                  distance (tests/python_venv.sh).
#
# Not in the sanitizer build: an instrumented library needs instrumented
# programs, and the install paths are the release build's.

if(HD_SANITIZE)
  return()
endif()

find_program(HD_PKG_CONFIG NAMES pkg-config pkgconf)
find_program(HD_MAKE NAMES make gmake)
set(_hd_inst ${CMAKE_CURRENT_SOURCE_DIR}/tests/install_check.sh)
set(_hd_inst_env "CC=${CMAKE_C_COMPILER};CMAKE=${CMAKE_COMMAND}")
if(HD_MPI)
  find_program(HD_INSTALL_MPIRUN NAMES mpirun mpiexec REQUIRED)
  list(APPEND _hd_inst_env "MPICC=${MPI_C_COMPILER}" "MPIRUN=${HD_INSTALL_MPIRUN}")
endif()
if(HD_PKG_CONFIG)
  list(APPEND _hd_inst_env "PKG_CONFIG=${HD_PKG_CONFIG}")
  add_test(NAME install COMMAND sh ${_hd_inst} prefix ${CMAKE_BINARY_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(install PROPERTIES ENVIRONMENT "${_hd_inst_env}" TIMEOUT 300)
else()
  message(STATUS "Install test: skipped (no pkg-config; scripts/deps.sh build installs it)")
endif()
if(HD_MAKE)
  add_test(NAME install_make COMMAND sh ${_hd_inst} make ${CMAKE_BINARY_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(install_make PROPERTIES ENVIRONMENT "${_hd_inst_env};MAKE=${HD_MAKE}" TIMEOUT 300)
endif()
if(HD_MAKE)
  add_test(NAME make_rules COMMAND sh ${_hd_inst} makefile ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(make_rules PROPERTIES ENVIRONMENT "MAKE=${HD_MAKE}" TIMEOUT 60)
endif()
add_test(NAME install_deps COMMAND sh ${_hd_inst} deps ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(install_deps PROPERTIES TIMEOUT 60)

# The venv install uses Debian's interpreter, as README does; the test fails
# (naming the package) when python3-venv or python3-wheel is missing, since
# `make test` installs them.
set(_hd_venv_candidates ${HD_PYTHON} /usr/bin/python3)
hd_find_python(_hd_venv_python "import os, sysconfig, numpy, setuptools
assert os.path.exists(os.path.join(sysconfig.get_paths()['include'], 'Python.h'))
" ${_hd_venv_candidates})
if(_hd_venv_python)
  add_test(NAME python_venv COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/tests/python_venv.sh
           ${_hd_venv_python} ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(python_venv PROPERTIES TIMEOUT 600)
else()
  message(STATUS "Python venv test: skipped (no interpreter among '${_hd_venv_candidates}' has "
                 "numpy, setuptools and Python.h; scripts/deps.sh python installs them)")
endif()
