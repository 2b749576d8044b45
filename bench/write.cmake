# write.cmake -- bench/write_bench: hd_write_field into LAS and LAZ on a
# generated file of 10^6 points, against copying it (docs/benchmarks.md,
# "Writing a field").  Not a test.
hd_add_bench(write_bench ${CMAKE_CURRENT_LIST_DIR}/write_bench.c
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/lazwrite.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/files.c)
target_include_directories(write_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal)
