# bench.cmake -- the engine benchmark (`make bench`, docs/benchmarks.md,
# "Engine"): bench/hd_bench, and with -DHD_BENCH_PEERS=ON the C++ peer
# programs it runs (nanoflann, PCL).  Not a test: nothing here is run by
# ctest.
hd_add_bench(hd_bench ${CMAKE_CURRENT_LIST_DIR}/bench.c)
# hd_bench prints the engine's plan (hd__engine_explain, src/engine/engine.h).
target_include_directories(hd_bench PRIVATE ${CMAKE_SOURCE_DIR}/src)
# engine_peak: the engine's memory peak and time, call after call.
hd_add_bench(engine_peak ${CMAKE_CURRENT_LIST_DIR}/engine_peak.c)
# page_cost: what fresh memory costs a byte, in small, populated and huge
# pages (docs/scale-out.md, "Memory pages on this machine").
hd_add_bench(page_cost ${CMAKE_CURRENT_LIST_DIR}/page_cost.c)

option(HD_BENCH_PEERS "Build the C++ peer programs of the engine benchmark (nanoflann, PCL)" OFF)
if(HD_BENCH_PEERS)
  include(CheckLanguage)
  check_language(CXX)
  if(NOT CMAKE_CXX_COMPILER)
    message(FATAL_ERROR "HD_BENCH_PEERS needs a C++ compiler (scripts/deps.sh bench installs g++)")
  endif()
  enable_language(CXX)
  find_package(OpenMP REQUIRED COMPONENTS CXX)
  find_path(HD_NANOFLANN_INCLUDE nanoflann.hpp REQUIRED)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(HD_PCL_KDTREE REQUIRED pcl_kdtree)
  # The peers are compiled as their users would compile them (-O3), except
  # that, like the library, they never fuse multiply-adds: their distances
  # are then the same doubles as the library's.
  add_executable(nanoflann_hd ${CMAKE_CURRENT_LIST_DIR}/peers/nanoflann_hd.cpp)
  target_include_directories(nanoflann_hd PRIVATE ${HD_NANOFLANN_INCLUDE})
  target_link_libraries(nanoflann_hd PRIVATE OpenMP::OpenMP_CXX)
  add_executable(pcl_hd ${CMAKE_CURRENT_LIST_DIR}/peers/pcl_hd.cpp)
  target_include_directories(pcl_hd PRIVATE ${HD_PCL_KDTREE_INCLUDE_DIRS})
  target_link_libraries(pcl_hd PRIVATE ${HD_PCL_KDTREE_LINK_LIBRARIES} OpenMP::OpenMP_CXX)
  foreach(t nanoflann_hd pcl_hd)
    set_target_properties(${t} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench
                                          CXX_STANDARD 14 CXX_STANDARD_REQUIRED ON)
    target_compile_options(${t} PRIVATE -O3)
  endforeach()
endif()
