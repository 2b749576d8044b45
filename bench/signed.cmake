# signed_bench: the sign's cost (hd_mesh_signed_distances: the closedness
# check, the winding tree, the winding number per point) on a closed torus,
# for docs/surfaces.md, "The sign".  Built with the project; not a test.
hd_add_bench(signed_bench ${CMAKE_CURRENT_LIST_DIR}/signed_bench.c)
target_include_directories(signed_bench PRIVATE ${CMAKE_SOURCE_DIR}/src)
