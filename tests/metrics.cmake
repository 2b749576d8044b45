# metrics.cmake -- scores at tolerances, DTU means and MONAI's surface Dice
# through the command line (tests/metrics_cli.py; numpy and scipy from
# Debian's /usr/bin/python3; python3-open3d is compared with when present),
# in both builds.  The Python module's masks and scores: python_metrics.cmake.
hd_find_python(HD_METRICS_PYTHON "import numpy, scipy" /usr/bin/python3 python3)
if(NOT HD_METRICS_PYTHON)
  message(STATUS "metrics_cli: skipped (no python3 with numpy and scipy; scripts/deps.sh python)")
  return()
endif()
add_test(NAME metrics_cli
  COMMAND ${HD_METRICS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/metrics_cli.py $<TARGET_FILE:hausdorff_cli>)
# without libnifti2 the mask cases are skipped (HD_NIFTI=0), the point sets' still run
set_tests_properties(metrics_cli PROPERTIES TIMEOUT 600 ENVIRONMENT "HD_NIFTI=$<BOOL:${HD_CLI_NIFTI}>")
# Label maps through the command line (--labels, --components, --csv):
# tests/labels_cli.py against a brute-force numpy reference, in both builds;
# NIfTI label maps need libnifti2.
if(HD_CLI_NIFTI)
  add_test(NAME labels_cli
    COMMAND ${HD_METRICS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/labels_cli.py $<TARGET_FILE:hausdorff_cli>)
  set_tests_properties(labels_cli PROPERTIES TIMEOUT 600)
endif()
