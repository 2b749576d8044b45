# algos_bench: times the paper's algorithms on 100K/100K Gaussian pairs
# (docs/algorithms.md).  Built with the project; not a test.
add_executable(algos_bench ${CMAKE_CURRENT_LIST_DIR}/algos_bench.c
                           ${CMAKE_CURRENT_LIST_DIR}/../tests/support/gen.c
    ${CMAKE_CURRENT_LIST_DIR}/support/benchutil.c)
target_include_directories(algos_bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../tests/support ${CMAKE_CURRENT_LIST_DIR}/support)
target_link_libraries(algos_bench PRIVATE hausdorff_static m)
set_target_properties(algos_bench PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
