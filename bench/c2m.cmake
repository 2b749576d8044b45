# c2m_bench: cloud to mesh (hd_mesh_distances) on near and far clouds,
# for docs/benchmarks.md, "Cloud to mesh".  Built with the project; not a test.
hd_add_bench(c2m_bench ${CMAKE_CURRENT_LIST_DIR}/c2m_bench.c)
