# fuzz_smoke.cmake -- every libFuzzer target (fuzz/fuzz.mk: the 9 readers as
# points, the 4 mesh readers sampled, NIfTI masks, the argument parser) is
# built with clang and run for FUZZ_SECONDS (3) from its seeds in
# tests/corpus/, which hold the inputs of every past finding: a reader or
# parser that regresses fails here.  libFuzzer's seed is fixed (FUZZ_SEED=1),
# so a failure replays; runs of 120-300 s a target find nothing on a tree
# that passes (docs/formats.md, "Fuzzing"), so 3 s cannot fail by chance on
# what a longer run would find routinely.  It builds in the build directory's
# fuzz-smoke/ and takes about two minutes on the shared 2-core machine (70 s
# building, 15 x 3 s fuzzing).  Added to the sanitizer build only (make test-asan, which
# installs clang through scripts/deps.sh fuzz), or anywhere with
# -DHD_FUZZ_SMOKE=ON.  Without clang the test fails: it never passes without
# fuzzing.
option(HD_FUZZ_SMOKE "Build and briefly run the libFuzzer targets as a test (needs clang)" OFF)
if(NOT (HD_ASAN_BUILD OR HD_FUZZ_SMOKE))
  return()
endif()
find_program(HD_FUZZ_SH NAMES sh)
set(HD_FUZZ_SMOKE_SECONDS 3 CACHE STRING "Seconds of fuzzing per target in the fuzz_smoke test")
add_test(NAME fuzz_smoke
  COMMAND ${CMAKE_COMMAND} -E env FUZZ_SECONDS=${HD_FUZZ_SMOKE_SECONDS} FUZZ_SEED=1 FUZZ_FRESH=1
          FUZZ_BUILD=${CMAKE_BINARY_DIR}/fuzz-smoke
          ${HD_FUZZ_SH} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/run.sh all)
set_tests_properties(fuzz_smoke PROPERTIES TIMEOUT 900 LABELS fuzz)
