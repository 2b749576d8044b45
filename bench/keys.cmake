# keys_bench: two callers of the Morton keys of packed doubles (the index,
# the engine's trees), for callgrind (docs/benchmarks.md, "The Morton keys
# of packed doubles").
hd_add_bench(keys_bench ${CMAKE_CURRENT_LIST_DIR}/keys_bench.c)
