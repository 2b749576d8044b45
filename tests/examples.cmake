# examples.cmake -- what the documentation shows, run:
#   cli_numtext_unit (tests/cli_numtext_unit.c) the numbers a person reads:
#               distances shortest, float32 coordinates as floats, ratios
#               and times for a person, singular counts (cli/numtext.c);
#   cli_report  (tests/cli_report.py) the report's numbers and words from
#               the tools, and hausdorff-mpi's own --help;
#   examples    (tests/examples.py) every example command of README.md,
#               `hausdorff --help`, `hausdorff-mpi --help` and
#               docs/hausdorff.1, run as written on bundled data (the
#               placeholder names are files of a fixture directory), each
#               exiting 0 with the distances the data's README gives; the
#               mpirun ones on 2 processes with --allow-run-as-root
#               --oversubscribe, when MPI is built.
add_executable(cli_numtext_unit tests/cli_numtext_unit.c cli/numtext.c ${HD_TEST_SUPPORT})
target_include_directories(cli_numtext_unit PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/cli
                           ${CMAKE_CURRENT_SOURCE_DIR}/tests/support)
target_link_libraries(cli_numtext_unit PRIVATE hausdorff_static m)
set_target_properties(cli_numtext_unit PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME cli_numtext_unit COMMAND cli_numtext_unit)

# numpy writes the NIfTI masks (tests/cli_analysis_support.py): Debian's python3-numpy.
hd_find_python(HD_EXAMPLES_PYTHON "import numpy" /usr/bin/python3 python3)
if(NOT HD_EXAMPLES_PYTHON)
  message(STATUS "cli_report, examples: skipped (no python3 with numpy; scripts/deps.sh python installs it)")
  return()
endif()
set(HD_EXAMPLES_MPI "")
if(HD_MPI)
  set(HD_EXAMPLES_MPI $<TARGET_FILE:hausdorff_mpi_cli>)
endif()
set(HD_EXAMPLES_ENV "HD_CLI_PNG=${HD_CLI_PNG}" "HD_CLI_NIFTI=${HD_CLI_NIFTI}" "HD_MPI_TOOL=${HD_EXAMPLES_MPI}")
foreach(t cli_report examples)
  add_test(NAME ${t} COMMAND ${HD_EXAMPLES_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/${t}.py
           $<TARGET_FILE:hausdorff_cli>)
  set_tests_properties(${t} PROPERTIES TIMEOUT 600 PROCESSORS 2 ENVIRONMENT "${HD_EXAMPLES_ENV}")
endforeach()
