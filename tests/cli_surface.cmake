# cli_surface.cmake -- `hausdorff --surface` (tests/cli_surface.py): points
# against a mesh's triangles, its text and JSON, the refusals.
find_program(HD_CLI_SURFACE_PYTHON NAMES python3)
if(HD_CLI_SURFACE_PYTHON)
  add_test(NAME cli_surface
    COMMAND ${HD_CLI_SURFACE_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_surface.py $<TARGET_FILE:hausdorff_cli>)
endif()
