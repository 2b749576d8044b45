# laz_lazperf.cmake -- the tests' LAZ writer (tests/internal/lazwrite.c)
# checked by an independent decoder, laz-perf (npm), through
# tests/laz_lazperf.py:
#
#   laz_lazperf_fixtures  offline: tests/lazgen writes every case, and each
#                         file is byte for byte the one laz-perf decoded, its
#                         points laz-perf's decoding (tests/laz_lazperf/,
#                         committed).  Fails, never skips: python3 only.
#   laz_lazperf_npm       the extra, where node, npm and the npm registry are
#                         reachable: installs laz-perf into the build
#                         directory and decodes the fixtures and the files
#                         lazgen writes now.  Without them CTest lists it as
#                         "Skipped" and its output says "NOT RUN" and why.
#                         Debian's nodejs and npm are not among `make test`'s
#                         packages (no registry but Debian's at test time).
#
# After a change to the writer's output, the fixtures are made again where
# npm is reachable:
#   python3 tests/laz_lazperf.py npm build/tests/lazgen tests/laz_lazperf build/laz-perf --update
#
# The writer (tests/internal/lazwrite.c) uses the coder's models from src/,
# so it is not in tests/support, which the api tests share without src/.
target_sources(test_io_laz PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/lazwrite.c)
target_sources(test_write_laz PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/lazwrite.c)
add_executable(lazgen tests/lazgen.c tests/internal/lazwrite.c tests/support/files.c tests/support/gen.c)
target_include_directories(lazgen PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src ${CMAKE_CURRENT_SOURCE_DIR}/tests/support
                           ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal)
target_link_libraries(lazgen PRIVATE hausdorff_static)
set_target_properties(lazgen PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
hd_python3_test(laz_lazperf_fixtures ${CMAKE_CURRENT_SOURCE_DIR}/tests/laz_lazperf.py offline $<TARGET_FILE:lazgen>
                ${CMAKE_CURRENT_SOURCE_DIR}/tests/laz_lazperf ${CMAKE_BINARY_DIR}/laz-perf-offline)
set_tests_properties(laz_lazperf_fixtures PROPERTIES TIMEOUT 300 LABELS laz)
hd_python3_test(laz_lazperf_npm ${CMAKE_CURRENT_SOURCE_DIR}/tests/laz_lazperf.py npm $<TARGET_FILE:lazgen>
                ${CMAKE_CURRENT_SOURCE_DIR}/tests/laz_lazperf ${CMAKE_BINARY_DIR}/laz-perf)
set_tests_properties(laz_lazperf_npm PROPERTIES TIMEOUT 900 LABELS "laz;npm" SKIP_RETURN_CODE 77)
