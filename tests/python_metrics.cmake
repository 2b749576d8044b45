# python_metrics.cmake -- hausdorff.masks and hausdorff.scores (the Python
# module, python/hausdorff/masks.py and scores.py) against MONAI's published
# surface Dice values, MONAI's and medpy's definitions rebuilt from scipy,
# and the command line (tests/python_metrics.py, pytest).  Needs the module
# (python.cmake, included before this file; not in the sanitizer build).
if(NOT TARGET hausdorff_python)
  return()
endif()
hd_find_python(HD_METRICS_PYTEST "import numpy, scipy, pytest" ${HD_PYTHON_EXE})
if(NOT HD_METRICS_PYTEST)
  message(STATUS "python_metrics: skipped (no scipy or pytest with ${HD_PYTHON_EXE})")
  return()
endif()
add_test(NAME python_metrics
  COMMAND ${HD_METRICS_PYTEST} -m pytest -q -p no:cacheprovider ${CMAKE_CURRENT_SOURCE_DIR}/tests/python_metrics.py
  WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
set_tests_properties(python_metrics PROPERTIES TIMEOUT 600 ENVIRONMENT
  "PYTHONPATH=${CMAKE_BINARY_DIR}/python;PYTHONDONTWRITEBYTECODE=1;HD_CLI=$<$<BOOL:${HD_CLI_NIFTI}>:$<TARGET_FILE:hausdorff_cli>>")
# Label maps, DeepMind's surfels and components (tests/python_labels.py):
# DeepMind's published surface_distance_test.py values, brute-force numpy
# references and scipy.ndimage.label.
add_test(NAME python_labels
  COMMAND ${HD_METRICS_PYTEST} -m pytest -q -p no:cacheprovider ${CMAKE_CURRENT_SOURCE_DIR}/tests/python_labels.py
  WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
set_tests_properties(python_labels PROPERTIES TIMEOUT 600 ENVIRONMENT
  "PYTHONPATH=${CMAKE_BINARY_DIR}/python;PYTHONDONTWRITEBYTECODE=1;HD_CLI=$<$<BOOL:${HD_CLI_NIFTI}>:$<TARGET_FILE:hausdorff_cli>>")
