# mpi.cmake -- the MPI scale-out's tests (cmake/mpi.cmake builds what they
# test; without MPI there is nothing to test and nothing is added).
#  - mpi_api_K: tests/mpi_api.c under `mpirun -n K` for K = 1, 2, 3, 4, 7:
#    hd_mpi_hausdorff equals hd_hausdorff bit for bit on the adversarial
#    sets and layouts, and failures on one rank are agreed by all.
#  - mpi_cli_*: tests/mpi_cli.py, hausdorff-mpi against hausdorff.
# Ranks are oversubscribed on purpose (2 cores, up to 7 ranks) and CI runs
# as root: hence --oversubscribe and --allow-run-as-root.  Open MPI's own
# allocations at exit are not freed (MPI_Finalize keeps its pools), which
# LeakSanitizer would report in the sanitizer build: there the tests run
# with the suppressions in tests/mpi_lsan.supp, which name only Open MPI's
# libraries (libmpi, libopen-pal, libopen-rte, their plug-ins, hwloc).
if(HD_MPI)
  find_program(HD_MPIEXEC NAMES ${MPIEXEC_EXECUTABLE} mpirun mpiexec)
  add_executable(mpi_api ${CMAKE_CURRENT_SOURCE_DIR}/tests/mpi_api.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_api PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_api PRIVATE hausdorff_mpi)
  set_target_properties(mpi_api PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  set(HD_MPIRUN ${HD_MPIEXEC} --oversubscribe --allow-run-as-root --mca btl self,vader,tcp)
  set(HD_MPI_ENV "LSAN_OPTIONS=suppressions=${CMAKE_CURRENT_SOURCE_DIR}/tests/mpi_lsan.supp:print_suppressions=0"
                 "OMPI_MCA_rmaps_base_oversubscribe=1")
  foreach(k 1 2 3 4 7)
    add_test(NAME mpi_api_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_api>)
    set_tests_properties(mpi_api_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
  endforeach()
endif()
