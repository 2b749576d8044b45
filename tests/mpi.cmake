# mpi.cmake -- the MPI scale-out's tests (cmake/mpi.cmake builds what they
# test; without MPI there is nothing to test and nothing is added).
#  - mpi_api_K: tests/api/mpi_api.c under `mpirun -n K`: hd_mpi_hausdorff equals
#    hd_hausdorff, and hd_mpi_distances hd_distances, bit for bit on the
#    adversarial sets and layouts, the partition balances uniform points
#    within 2 %, and a failure on one rank is agreed by all.  K = 1, 2, 3, 4, 7 here; the
#    sanitizer build runs K = 3 only.
#  - mpi_figures_K: tests/api/mpi_figures.c under `mpirun -n K`:
#    hd_mpi_summarize, hd_mpi_percentile_of and hd_mpi_histogram equal the
#    single-process functions bit for bit however the values are spread,
#    and failures are agreed.  The same K as mpi_api.
#  - mpi_percentile_K: tests/api/mpi_percentile.c under `mpirun -n K`:
#    hd_mpi_hausdorff_percentile equals sorting every exact distance and
#    hd_hausdorff_percentile bit for bit (issue 39's cases, ties and
#    duplicates, three layouts, 1 and 2 threads), without every distance
#    on the cases a-c, and failures are agreed.  K = 1, 2, 3, 4 (3 in the
#    sanitizer build).
#  - mpi_partition_K: tests/internal/mpi_partition.c under `mpirun -n K`,
#    white-box: the partition (src/mpi/rcb.c) balances uniform, clustered
#    and copied points within 5 % with 1024 first samples a rank and with
#    the fewest (64) that many ranks get, and that count keeps rank 0's
#    samples bounded.  The same K as mpi_api.
#  - mpi_shapes_K: tests/api/mpi_shapes.c under `mpirun -n K`: the shapes
#    of issue 41 (cubes far apart and 2 apart, a tiny side both ways, a
#    tower in one epoch, a lattice against its half-step shift, cubes
#    overlapping by half) give hd_hausdorff's and hd_directed's answers bit
#    for bit, at most 2 % of the points are forwarded, and the cells
#    (src/mpi/prune.c) save bytes where some can pass.  The same K as mpi_api.
#  - mpi_tiny_K: tests/api/mpi_tiny.c under `mpirun -n K`: a tiny side
#    replicated on every rank (src/mpi/tiny.c), both ways, with ties
#    across ranks: results and per-point answers bit for bit, and only the
#    tiny side moved.  The same K as mpi_api.
#  - mpi_gidx: tests/internal/mpi_gidx.c, the encoded global indices of
#    the local sets (src/mpi/gidx.c) read back by position and by cursor.
#  - mpi_memory: tests/internal/mpi_memory.c, the call's buffers charged at
#    what they hold (src/mpi/context.c), scratch ones rounded to huge pages.
#  - mpi_nearest: tests/internal/mpi_nearest.c, the per-point searches of a
#    local set (src/mpi/slab.c): a few askers by one pass over it, more by
#    the slab, both the brute force's answer, ties to the smallest index.
#  - mpi_cli_3: tests/mpi_cli.py, hausdorff-mpi on 3 ranks against
#    hausdorff (JSON and text, tiles, scales, a bad tile on one rank, the
#    --distances files byte for byte and their failures: an unwritable
#    name, a full file system (a 64 KiB tmpfs: mounting needs root, and the
#    case says SKIPPED without it) and a size limit (ulimit -f) on the
#    ranks; the figures and the pictures).
# Ranks are oversubscribed on purpose (2 cores, up to 7 ranks) and CI runs
# as root: hence --oversubscribe and --allow-run-as-root.  Under the
# sanitizers LeakSanitizer is off for these tests: Open MPI does not free
# what its plug-ins allocate and unloads them before exit, so the reports
# cannot even be suppressed by library name.  The library's own buffers are
# checked instead by an assert (src/mpi/mpi.c: the call's count of bytes
# held is 0 when it returns), and AddressSanitizer and UBSan stay on.  The
# times (Release, 2 shared cores): mpi_api 1, 3, 2.5-4.5, 3.5 and 6-13 s;
# mpi_figures 1, 1.5, 4.4, 3.4 and 5.8 s; mpi_cli_3 90-110 s (load 7-8);
# sanitizers: mpi_api_3 14-25 s, mpi_figures_3 8 s, mpi_cli_3 100-160 s.
# mpi_percentile 5, 15-33, 15 and 14-26 s at load 12-13.
if(HD_MPI)
  find_program(HD_MPIEXEC NAMES mpirun mpiexec REQUIRED)
  add_executable(mpi_api ${CMAKE_CURRENT_SOURCE_DIR}/tests/api/mpi_api.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_api PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_api PRIVATE hausdorff_mpi)
  set_target_properties(mpi_api PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  # mpi_figures_K: tests/api/mpi_figures.c, hd_mpi_summarize,
  # hd_mpi_percentile_of and hd_mpi_histogram against the single process.
  add_executable(mpi_figures ${CMAKE_CURRENT_SOURCE_DIR}/tests/api/mpi_figures.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_figures PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_figures PRIVATE hausdorff_mpi)
  set_target_properties(mpi_figures PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_executable(mpi_percentile ${CMAKE_CURRENT_SOURCE_DIR}/tests/api/mpi_percentile.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_percentile PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_percentile PRIVATE hausdorff_mpi)
  set_target_properties(mpi_percentile PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_executable(mpi_shapes ${CMAKE_CURRENT_SOURCE_DIR}/tests/api/mpi_shapes.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_shapes PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_shapes PRIVATE hausdorff_mpi)
  set_target_properties(mpi_shapes PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_executable(mpi_tiny ${CMAKE_CURRENT_SOURCE_DIR}/tests/api/mpi_tiny.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_tiny PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
  target_link_libraries(mpi_tiny PRIVATE hausdorff_mpi)
  set_target_properties(mpi_tiny PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_executable(mpi_partition ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/mpi_partition.c ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/gen.c)
  target_include_directories(mpi_partition PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(mpi_partition PRIVATE hausdorff_mpi)
  set_target_properties(mpi_partition PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  set(HD_MPIRUN ${HD_MPIEXEC} --oversubscribe --allow-run-as-root)
  set(HD_MPI_ENV "OMPI_ALLOW_RUN_AS_ROOT=1" "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
  if(HD_SANITIZE)
    set(HD_MPI_RANKS 3)
    list(APPEND HD_MPI_ENV "ASAN_OPTIONS=detect_leaks=0")
  else()
    set(HD_MPI_RANKS 1 2 3 4 7)
  endif()
  foreach(k ${HD_MPI_RANKS})
    add_test(NAME mpi_api_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_api>)
    set_tests_properties(mpi_api_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
    add_test(NAME mpi_figures_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_figures>)
    set_tests_properties(mpi_figures_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
    add_test(NAME mpi_shapes_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_shapes>)
    set_tests_properties(mpi_shapes_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
    add_test(NAME mpi_tiny_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_tiny>)
    set_tests_properties(mpi_tiny_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
    if(NOT k EQUAL 7)
      add_test(NAME mpi_percentile_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_percentile>)
      set_tests_properties(mpi_percentile_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
    endif()
    add_test(NAME mpi_partition_${k} COMMAND ${HD_MPIRUN} -n ${k} $<TARGET_FILE:mpi_partition>)
    set_tests_properties(mpi_partition_${k} PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
  endforeach()
  # mpi_gidx: tests/internal/mpi_gidx.c, the local sets' encoded global
  # indices (src/mpi/gidx.c), white-box and without mpirun (no MPI call).
  add_executable(mpi_gidx ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/mpi_gidx.c ${HD_TEST_SUPPORT})
  target_include_directories(mpi_gidx PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(mpi_gidx PRIVATE hausdorff_mpi)
  set_target_properties(mpi_gidx PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME mpi_gidx COMMAND mpi_gidx)
  # mpi_memory: tests/internal/mpi_memory.c, how the call's buffers are
  # charged (src/mpi/context.c), white-box and without mpirun.
  add_executable(mpi_memory ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/mpi_memory.c ${HD_TEST_SUPPORT})
  target_include_directories(mpi_memory PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(mpi_memory PRIVATE hausdorff_mpi)
  set_target_properties(mpi_memory PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME mpi_memory COMMAND mpi_memory)
  # mpi_nearest: tests/internal/mpi_nearest.c, the per-point searches of a
  # rank's local set (src/mpi/slab.c), white-box and without mpirun.
  add_executable(mpi_nearest ${CMAKE_CURRENT_SOURCE_DIR}/tests/internal/mpi_nearest.c ${HD_TEST_SUPPORT})
  target_include_directories(mpi_nearest PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(mpi_nearest PRIVATE hausdorff_mpi)
  set_target_properties(mpi_nearest PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME mpi_nearest COMMAND mpi_nearest)
  hd_python3_test(mpi_cli_3 ${CMAKE_CURRENT_SOURCE_DIR}/tests/mpi_cli.py
                  $<TARGET_FILE:hausdorff_cli> $<TARGET_FILE:hausdorff_mpi_cli> 3 ${HD_MPIRUN})
  set_tests_properties(mpi_cli_3 PROPERTIES TIMEOUT 300 ENVIRONMENT "${HD_MPI_ENV}" PROCESSORS 2)
endif()
