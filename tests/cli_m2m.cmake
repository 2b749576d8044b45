# cli_m2m.cmake -- `hausdorff --surface` with a mesh as A (tests/cli_m2m.py):
# the distance from a surface as an enclosure, --tolerance, --within, a
# point set as B, the refusals and bad meshes.
find_program(HD_CLI_M2M_PYTHON NAMES python3)
if(HD_CLI_M2M_PYTHON)
  add_test(NAME cli_m2m
    COMMAND ${HD_CLI_M2M_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_m2m.py $<TARGET_FILE:hausdorff_cli>)
endif()
