# layers.cmake -- the layering check (scripts/check_layers.py): lower folders
# of src/ never include higher ones' headers, siblings never each other's,
# cli/ the public header only; tests/layers_check.py also shows the check
# failing on trees that break the rule.  Without python3 the test fails
# (make test installs it), never skips (hd_python3_test).
hd_python3_test(layers ${CMAKE_CURRENT_SOURCE_DIR}/tests/layers_check.py)
set_tests_properties(layers PROPERTIES TIMEOUT 60)
