# read.cmake -- bench/read_bench: read throughput per format on a large
# generated file, against `cat` (docs/benchmarks.md, "Reading").  Not a test.
hd_add_bench(read_bench ${CMAKE_CURRENT_LIST_DIR}/read_bench.c)
