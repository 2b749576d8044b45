# m2m_dense.cmake -- the independent dense check of surface-to-surface
# enclosures (tests/m2m_dense_check.h), public API only: m2m_dense_test
# (the check on closed-form cases, then hd_surface_hausdorff's enclosures on
# seeded random small cases) and the m2m_dense program that the benchmark
# (bench/m2m_bench.py) runs on every case.
add_library(m2m_dense_check STATIC tests/m2m_dense_check.c)
target_include_directories(m2m_dense_check PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/tests)
target_link_libraries(m2m_dense_check PUBLIC hausdorff_static m)
add_executable(m2m_dense tests/m2m_dense.c)
target_link_libraries(m2m_dense PRIVATE m2m_dense_check)
add_executable(m2m_dense_test tests/m2m_dense_test.c ${HD_TEST_SUPPORT})
target_include_directories(m2m_dense_test PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
target_link_libraries(m2m_dense_test PRIVATE m2m_dense_check)
set_target_properties(m2m_dense m2m_dense_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME m2m_dense COMMAND m2m_dense_test WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
