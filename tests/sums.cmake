# sums.cmake -- tests/support/sums_cases.h (the expected sums of
# tests/api/test_sums.c, math.fsum's) is what tests/gen_sums.py writes:
# the generator and the table cannot drift apart.  About 3 s.
# Without python3 the test fails, never skips (hd_python3_test).
hd_python3_test(sums_cases_current ${CMAKE_CURRENT_SOURCE_DIR}/tests/gen_sums.py --check
                ${CMAKE_CURRENT_SOURCE_DIR}/tests/support/sums_cases.h)
set_tests_properties(sums_cases_current PROPERTIES TIMEOUT 120)
