# experiments: reruns the experiments of the paper's Section 6 (`make
# experiments`, docs/paper-reproduction.md; bench/plot_experiments.py draws
# the tables and figures from its output).  Built with the project; not a test.
add_executable(experiments ${CMAKE_CURRENT_LIST_DIR}/experiments.c
                           ${CMAKE_CURRENT_LIST_DIR}/../tests/support/gen.c
    ${CMAKE_CURRENT_LIST_DIR}/support/benchutil.c)
target_include_directories(experiments PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../tests/support ${CMAKE_CURRENT_LIST_DIR}/support)
target_link_libraries(experiments PRIVATE hausdorff_static m)
set_target_properties(experiments PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
