# read.cmake -- bench/read_bench: read throughput per format on a large
# generated file, against `cat` (docs/benchmarks.md, "Reading").  Not a test.
hd_add_bench(read_bench ${CMAKE_CURRENT_LIST_DIR}/read_bench.c
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/lazwrite.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/files.c)
# the LAZ rows' writer shares the coder's models (src/io/lazcoder.h)
target_include_directories(read_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal)
