# layers.cmake -- the layering check (scripts/check_layers.py): from the
# sources, lower folders of src/ never include higher ones' headers nor any
# folder's private headers, siblings never each other's, cli/ the public
# header only; from this build's objects (nm), no folder uses a symbol of a
# higher one or declares one, and no folder's files (nor cli/'s, --cli) use
# each other in a cycle.  tests/layers_check.py also shows the check failing
# on trees that break the rules (compiled with this build's C compiler).
# Without python3 the test fails (make test installs it), never skips
# (hd_python3_test).
hd_python3_test(layers ${CMAKE_CURRENT_SOURCE_DIR}/tests/layers_check.py ${CMAKE_BINARY_DIR})
set_tests_properties(layers PROPERTIES TIMEOUT 120 ENVIRONMENT "CC=${CMAKE_C_COMPILER}")
