# experiments: reruns the experiments of the paper's Section 6 (`make
# experiments`, docs/paper-reproduction.md; bench/plot_experiments.py draws
# the tables and figures from its output).  Built with the project; not a test.
hd_add_bench(experiments ${CMAKE_CURRENT_LIST_DIR}/experiments.c)
