# read.cmake -- bench/read_bench: read throughput per format on a large
# generated file, against `cat` (docs/benchmarks.md, "Reading").  Not a test.
add_executable(read_bench ${CMAKE_CURRENT_SOURCE_DIR}/bench/read_bench.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
target_include_directories(read_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
target_link_libraries(read_bench PRIVATE hausdorff_static)
set_target_properties(read_bench PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
