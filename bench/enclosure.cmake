# enclosure_bench: the surface-to-surface enclosure (hd_surface_hausdorff) of
# a bundled model against its vertex-clustered or perturbed copy.
hd_add_bench(enclosure_bench ${CMAKE_CURRENT_LIST_DIR}/enclosure_bench.c)
