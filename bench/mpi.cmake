# mpi.cmake -- the MPI scale-out's benchmark (docs/scale-out.md):
# bench/mpi_bench, run under mpirun by hand.  Not a test.
if(HD_MPI)
  hd_add_bench(mpi_bench ${CMAKE_CURRENT_LIST_DIR}/mpi_bench.c)
  target_link_libraries(mpi_bench PRIVATE hausdorff_mpi)
endif()
