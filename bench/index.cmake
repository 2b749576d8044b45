# index_bench: the index's build and one directed query on Gaussian sets,
# for callgrind (docs/benchmarks.md, "The Morton keys of packed doubles").
hd_add_bench(index_bench ${CMAKE_CURRENT_LIST_DIR}/index_bench.c)
