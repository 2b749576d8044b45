# cli_analysis.cmake -- the analysis tests written in Python (numpy is the
# reference for percentiles and histograms, so they need an interpreter that
# has it: Debian's /usr/bin/python3, installed by scripts/deps.sh python).
#   cli_analysis        the command line's analysis options
#   cli_analysis_nifti  NIfTI masks (only when the tool has libnifti2)
#   cli_nifti_hostile   NIfTI headers that lie: refused, one line, exit 2
#   cli_nifti_reference MONAI's and medpy's published test values, their
#                       masks written with nibabel (python3-nibabel,
#                       scripts/deps.sh test)
#   cli_analysis_lib    hd_percentiles / hd_histogram against numpy through
#                       ctypes (not in the sanitizer build: an ASan library
#                       cannot be loaded into an uninstrumented interpreter)
hd_find_python(HD_ANALYSIS_PYTHON "import numpy, scipy" /usr/bin/python3 python3)
if(NOT HD_ANALYSIS_PYTHON)
  message(STATUS "analysis tests in Python: skipped (no python3 with numpy and scipy; "
                 "scripts/deps.sh python installs them)")
  return()
endif()

add_test(NAME cli_analysis
  COMMAND ${HD_ANALYSIS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_analysis.py $<TARGET_FILE:hausdorff_cli>)
set_tests_properties(cli_analysis PROPERTIES ENVIRONMENT "HD_CLI_PNG=${HD_CLI_PNG}" TIMEOUT 600)
if(HD_CLI_NIFTI)
  add_test(NAME cli_analysis_nifti
    COMMAND ${HD_ANALYSIS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_analysis_nifti.py
            $<TARGET_FILE:hausdorff_cli>)
  set_tests_properties(cli_analysis_nifti PROPERTIES TIMEOUT 600)
  add_test(NAME cli_nifti_hostile
    COMMAND ${HD_ANALYSIS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_nifti_hostile.py
            $<TARGET_FILE:hausdorff_cli>)
  set_tests_properties(cli_nifti_hostile PROPERTIES TIMEOUT 600)
  hd_find_python(HD_NIBABEL_PYTHON "import numpy, scipy, nibabel" ${HD_ANALYSIS_PYTHON})
  if(HD_NIBABEL_PYTHON)
    add_test(NAME cli_nifti_reference
      COMMAND ${HD_NIBABEL_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_nifti_reference.py
              $<TARGET_FILE:hausdorff_cli>)
    set_tests_properties(cli_nifti_reference PROPERTIES TIMEOUT 600)
  else()
    message(STATUS "cli_nifti_reference: skipped (no nibabel; scripts/deps.sh test installs python3-nibabel)")
  endif()
endif()
if(NOT HD_SANITIZE)
  add_test(NAME cli_analysis_lib
    COMMAND ${HD_ANALYSIS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/cli_analysis_lib.py
            $<TARGET_FILE:hausdorff>)
endif()
