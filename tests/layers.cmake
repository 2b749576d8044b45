# layers.cmake -- the layering check (scripts/check_layers.py): lower folders
# of src/ never include higher ones' headers, siblings never each other's,
# cli/ the public header only; tests/layers_check.py also shows the check
# failing on trees that break the rule.  python3 is required (make test
# installs it), so a missing interpreter fails the configure, not the rule.
find_program(HD_LAYERS_PYTHON NAMES python3 REQUIRED)
add_test(NAME layers COMMAND ${HD_LAYERS_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/tests/layers_check.py)
set_tests_properties(layers PROPERTIES TIMEOUT 60)
