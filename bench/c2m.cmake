# c2m_bench: cloud to mesh (hd_mesh_distances) on near and far clouds,
# for docs/benchmarks.md, "Cloud to mesh" (bench/c2m_run.py drives it and
# the peers: `make bench`, `make bench-c2m`).  Built with the project; not
# a test.  It includes src/ for the brute-force check (hd__tri_nearest).
hd_add_bench(c2m_bench ${CMAKE_CURRENT_LIST_DIR}/c2m_bench.c)
target_include_directories(c2m_bench PRIVATE ${CMAKE_SOURCE_DIR}/src)

# The CGAL peer (AABB tree, double), with -DHD_BENCH_PEERS=ON (bench.cmake)
# or -DHD_BENCH_CGAL=ON (this peer alone):
# compiled as its users would compile it (-O3, CGAL's NDEBUG).
option(HD_BENCH_CGAL "Build the CGAL peer of the cloud-to-mesh benchmark" OFF)
if(HD_BENCH_PEERS OR HD_BENCH_CGAL)
  enable_language(CXX)
  find_path(HD_CGAL_INCLUDE CGAL/AABB_tree.h REQUIRED)
  find_library(HD_GMP gmp REQUIRED)
  find_library(HD_MPFR mpfr REQUIRED)
  add_executable(c2m_cgal ${CMAKE_CURRENT_LIST_DIR}/peers/c2m_cgal.cpp)
  target_include_directories(c2m_cgal PRIVATE ${HD_CGAL_INCLUDE})
  target_link_libraries(c2m_cgal PRIVATE ${HD_MPFR} ${HD_GMP})
  target_compile_definitions(c2m_cgal PRIVATE NDEBUG)
  target_compile_options(c2m_cgal PRIVATE -O3)
  set_target_properties(c2m_cgal PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench
                                            CXX_STANDARD 14 CXX_STANDARD_REQUIRED ON)
endif()
