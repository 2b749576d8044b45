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
#   cli_writeback (tests/cli_writeback.py) --distances into A's own format
#               and --farther-than / --nearer-than: the fields written back
#               equal the --distances table bit for bit (PLY, LAS, LAZ), the
#               refusals before reading, exit 3 and no file when one cannot
#               be written.
#   cli_tiles_unit (tests/cli_tiles_unit.c) cli/tiles.c as hausdorff-mpi
#               uses it: tiles_share, tiles_read of a range, tiles_locate.
add_executable(cli_tiles_unit tests/cli_tiles_unit.c cli/tiles.c cli/nifti.c ${HD_TEST_SUPPORT})
target_include_directories(cli_tiles_unit PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/cli
                           ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
target_link_libraries(cli_tiles_unit PRIVATE hausdorff_static)
set_target_properties(cli_tiles_unit PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME cli_tiles_unit COMMAND cli_tiles_unit WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})

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
add_test(NAME cli_writeback
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_writeback.py $<TARGET_FILE:hausdorff_cli>
  $<TARGET_FILE:lazgen>)
set_tests_properties(cli_writeback PROPERTIES TIMEOUT 300)
add_test(NAME cli_tiles
  COMMAND ${HD_CLI_IO_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_tiles.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_tiles PROPERTIES TIMEOUT 300)
