# m2m.cmake -- the surface-to-surface benchmark (`make bench-m2m`,
# bench/m2m_bench.py, docs/benchmarks.md "Surface to surface"): the case
# generator, the timing of hd_surface_hausdorff, and with HD_BENCH_CGAL (or
# HD_BENCH_PEERS) the CGAL peer.  Built with the project; not a test (the
# dense check it runs is tests/m2m_dense.cmake's).
hd_add_bench(m2m_cases ${CMAKE_CURRENT_LIST_DIR}/m2m_cases.c)
hd_add_bench(m2m_run ${CMAKE_CURRENT_LIST_DIR}/m2m_run.c)

option(HD_BENCH_CGAL "Build the CGAL peer of the surface-to-surface benchmark (libcgal-dev)" OFF)
if(HD_BENCH_CGAL OR HD_BENCH_PEERS)
  include(CheckLanguage)
  check_language(CXX)
  if(NOT CMAKE_CXX_COMPILER)
    message(FATAL_ERROR "The CGAL peer needs a C++ compiler (scripts/deps.sh cgal installs g++)")
  endif()
  enable_language(CXX)
  find_path(HD_CGAL_INCLUDE CGAL/Polygon_mesh_processing/distance.h REQUIRED)
  find_library(HD_GMP_LIB gmp REQUIRED)
  find_library(HD_MPFR_LIB mpfr REQUIRED)
  # As its users compile it (-O3, CGAL's assertions off), without fused
  # multiply-adds like the library.
  add_executable(m2m_cgal ${CMAKE_CURRENT_LIST_DIR}/peers/m2m_cgal.cpp)
  target_include_directories(m2m_cgal PRIVATE ${HD_CGAL_INCLUDE})
  target_link_libraries(m2m_cgal PRIVATE ${HD_MPFR_LIB} ${HD_GMP_LIB})
  target_compile_definitions(m2m_cgal PRIVATE NDEBUG CGAL_NDEBUG)
  target_compile_options(m2m_cgal PRIVATE -O3)
  set_target_properties(m2m_cgal PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench
                                            CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON)
endif()
