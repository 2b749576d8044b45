# laz_lazperf.cmake -- the tests' LAZ writer (tests/internal/lazwrite.c)
# checked by an independent decoder: tests/lazgen writes LAZ files in every
# scheme the reader decodes, tests/laz_lazperf.py installs the npm package
# laz-perf into the build directory (npm, registry needed) and compares its
# decoding with the points written.  Fails, never skips, without python3,
# node or npm (scripts/deps.sh test installs nodejs and npm).
# The writer (tests/internal/lazwrite.c) uses the coder's models from src/,
# so it is not in tests/support, which the api tests share without src/.
target_sources(test_io_laz PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/lazwrite.c)
add_executable(lazgen tests/lazgen.c tests/internal/lazwrite.c tests/support/files.c tests/support/gen.c)
target_include_directories(lazgen PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src ${CMAKE_CURRENT_SOURCE_DIR}/tests/support
                           ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal)
target_link_libraries(lazgen PRIVATE hausdorff_static)
set_target_properties(lazgen PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
find_program(HD_LAZPERF_PYTHON NAMES python3)
if(NOT HD_LAZPERF_PYTHON)
  set(HD_LAZPERF_PYTHON python3)
endif()
add_test(NAME laz_lazperf
  COMMAND ${HD_LAZPERF_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/laz_lazperf.py $<TARGET_FILE:lazgen>
          ${CMAKE_BINARY_DIR}/laz-perf)
set_tests_properties(laz_lazperf PROPERTIES TIMEOUT 900 LABELS laz)
