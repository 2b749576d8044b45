# cli_io.cmake -- the command line's reading behaviour (tests/cli_io.py):
# exit codes and messages for bad input in every format, standard input,
# --format/--formats/--sample/--version/--help, and the progress bar on a
# terminal.  Standard-library Python only, so any python3 will do.
find_program(HD_CLI_IO_PYTHON NAMES python3)
if(NOT HD_CLI_IO_PYTHON)
  message(STATUS "cli_io: skipped (no python3)")
  return()
endif()
add_test(NAME cli_io
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_io.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_io PROPERTIES TIMEOUT 300)
