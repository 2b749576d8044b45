# m2m.cmake -- the surface-to-surface benchmark (bench/m2m_bench.py,
# docs/benchmarks.md "Surface to surface"): the case generator.  Built with
# the project; not a test.
hd_add_bench(m2m_cases ${CMAKE_CURRENT_LIST_DIR}/m2m_cases.c)
