# analysis_bench: per-point distances (hd_distances) against the Hausdorff
# distance alone (auto engine and the kd-tree baseline) and the memory pass,
# for docs/benchmarks.md, "Analysis".  Built with the project; not a test.
add_executable(analysis_bench ${CMAKE_CURRENT_LIST_DIR}/analysis_bench.c
                              ${CMAKE_CURRENT_LIST_DIR}/../tests/support/gen.c
    ${CMAKE_CURRENT_LIST_DIR}/support/benchutil.c)
target_include_directories(analysis_bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../tests/support ${CMAKE_CURRENT_LIST_DIR}/support)
target_link_libraries(analysis_bench PRIVATE hausdorff_static m)
set_target_properties(analysis_bench PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
