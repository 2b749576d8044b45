# algos_bench: times the paper's algorithms on 100K/100K Gaussian pairs
# (docs/algorithms.md).  Built with the project; not a test.
hd_add_bench(algos_bench ${CMAKE_CURRENT_LIST_DIR}/algos_bench.c)
