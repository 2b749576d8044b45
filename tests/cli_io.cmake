# cli_io.cmake -- the command line's reading and writing behaviour:
#   cli_io      (tests/cli_io.py) exit codes and messages for bad input in
#               every format, standard input, --format/--formats/--sample/
#               --version/--help, and the progress bar on a terminal;
#   cli_output  (tests/cli_output.py) lost output is exit 3, never success:
#               standard output on /dev/full or closed, files that cannot be
#               written or finished leave nothing (pairs: neither file),
#               outputs naming an input are refused (exit 1);
#   cli_tiles   (tests/cli_tiles.py) a side as a directory or @LIST of
#               files: their points concatenated in order, bit-identical to
#               one concatenated file, the witness by file and index, every
#               bad tile or list line named.
# Standard-library Python only, so any python3 will do.
find_program(HD_CLI_IO_PYTHON NAMES python3)
if(NOT HD_CLI_IO_PYTHON)
  message(STATUS "cli_io, cli_output, cli_tiles: skipped (no python3)")
  return()
endif()
add_test(NAME cli_io
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_io.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_io PROPERTIES TIMEOUT 300)
add_test(NAME cli_output
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_output.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_output PROPERTIES TIMEOUT 300)
add_test(NAME cli_tiles
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_tiles.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_tiles PROPERTIES TIMEOUT 300)
