# mesh.cmake -- the point-to-triangle kernel's cost (bench/tri_bench.c,
# docs/surfaces.md).
hd_add_bench(tri_bench ${CMAKE_CURRENT_LIST_DIR}/tri_bench.c)
target_include_directories(tri_bench PRIVATE ${CMAKE_SOURCE_DIR}/src)
