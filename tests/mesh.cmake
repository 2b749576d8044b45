# mesh.cmake -- the point-to-triangle kernel against exact rational
# arithmetic in Python (tests/tri_reference.py): 10^6 seeded cases in the
# release build, 10^5 under the sanitizers.  tri_cases is the kernel as a
# filter (tests/internal/tri_cases.c).
add_executable(tri_cases tests/internal/tri_cases.c)
target_include_directories(tri_cases PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
target_link_libraries(tri_cases PRIVATE hausdorff_static)
set_target_properties(tri_cases PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
if(HD_ASAN_BUILD)
  set(HD_TRI_CASES 100000)
else()
  set(HD_TRI_CASES 1000000)
endif()
hd_python3_test(tri_reference ${CMAKE_CURRENT_SOURCE_DIR}/tests/tri_reference.py
                $<TARGET_FILE:tri_cases> --cases ${HD_TRI_CASES})
