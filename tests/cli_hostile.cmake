# cli_hostile.cmake -- cli_hostile (tests/cli_hostile.py): hostile inputs
# and outputs of the command line: a Chamfer distance whose sum of squares
# is beyond DBL_MAX, file names that are not UTF-8 or hold control
# characters (valid JSON, escaped text), output FIFOs without a reader
# (exit 3 after --fifo-wait), a subnormal --max-distance, a directory that
# cannot hold the temporary, messages longer than the error record, a file
# that cannot be mapped for want of memory (exit 3).
find_program(HD_CLI_HOSTILE_PYTHON NAMES python3)
if(NOT HD_CLI_HOSTILE_PYTHON)
  message(STATUS "cli_hostile: skipped (no python3)")
  return()
endif()
set(HD_CLI_HOSTILE_ARGS)
if(HD_SANITIZE)
  set(HD_CLI_HOSTILE_ARGS --sanitized)
endif()
add_test(NAME cli_hostile
  COMMAND ${HD_CLI_HOSTILE_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_hostile.py $<TARGET_FILE:hausdorff_cli>
          ${HD_CLI_HOSTILE_ARGS})
set_tests_properties(cli_hostile PROPERTIES TIMEOUT 300)
