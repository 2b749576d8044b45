# analysis_bench: per-point distances (hd_distances) against the Hausdorff
# distance alone (auto engine and the kd-tree baseline) and the memory pass,
# for docs/benchmarks.md, "Analysis".  Built with the project; not a test.
hd_add_bench(analysis_bench ${CMAKE_CURRENT_LIST_DIR}/analysis_bench.c)
# summarize_bench: hd_summarize's exact sums per value, against a plain loop.
hd_add_bench(summarize_bench ${CMAKE_CURRENT_LIST_DIR}/summarize_bench.c)
# percentile_bench: HD95 from bands (hd_hausdorff_percentile) against every
# distance then a selection, on issue 39's cases a-e.
hd_add_bench(percentile_bench ${CMAKE_CURRENT_LIST_DIR}/percentile_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/field_cases.c)
# field_bench: the per-point field (hd_distances) on issue 39's cases a-e,
# phase by phase (build, each direction), against the Hausdorff distance.
hd_add_bench(field_bench ${CMAKE_CURRENT_LIST_DIR}/field_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/field_cases.c)
target_include_directories(field_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
# field_histogram_bench: histograms from bounds (hd_hausdorff_histogram)
# against every distance then hd_histogram, on issue 39's cases a-e.
hd_add_bench(field_histogram_bench ${CMAKE_CURRENT_LIST_DIR}/field_histogram_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/field_cases.c)
# percentile_mpi_bench (under mpirun): hausdorff-mpi's percentile without
# every distance (hd_mpi_hausdorff_percentile) against every distance over
# the ranks then hd_mpi_percentile_of, on issue 39's cases a-e.
if(HD_MPI)
  hd_add_bench(percentile_mpi_bench ${CMAKE_CURRENT_LIST_DIR}/percentile_mpi_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/field_cases.c)
  target_link_libraries(percentile_mpi_bench PRIVATE hausdorff_mpi)
endif()
