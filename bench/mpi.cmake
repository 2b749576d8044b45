# mpi.cmake -- the MPI scale-out's benchmarks (docs/scale-out.md), run by
# hand, not tests: bench/mpi_bench (under mpirun) and bench/partition_bench
# (RCB against Morton ranges, one process, needs no MPI), both on the
# scenes of bench/support/scene.c; bench/rcb_bench (rank 0's tree over the
# first samples at many ranks, one process, no mpirun); bench/mpi_copy
# (MPI's own CPU a record of an all-to-all, under mpirun).
hd_add_bench(partition_bench ${CMAKE_CURRENT_LIST_DIR}/partition_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/scene.c)
if(HD_MPI)
  hd_add_bench(mpi_bench ${CMAKE_CURRENT_LIST_DIR}/mpi_bench.c ${CMAKE_CURRENT_LIST_DIR}/support/scene.c)
  target_link_libraries(mpi_bench PRIVATE hausdorff_mpi)
  hd_add_bench(rcb_bench ${CMAKE_CURRENT_LIST_DIR}/rcb_bench.c)
  target_include_directories(rcb_bench PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(rcb_bench PRIVATE hausdorff_mpi)
  # mpi_copy: MPI's own CPU time a record of the exchange's all-to-all.
  hd_add_bench(mpi_copy ${CMAKE_CURRENT_LIST_DIR}/mpi_copy.c)
  target_link_libraries(mpi_copy PRIVATE MPI::MPI_C)
endif()
