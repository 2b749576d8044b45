# hd_find_python(OUT PROBE CANDIDATE...) -- the first interpreter among the
# candidates for which `CANDIDATE -c PROBE` succeeds, or "" in OUT.
#
# Debian's numpy, scipy and setuptools live under /usr/bin/python3; another
# python3 earlier on PATH (pyenv, a virtual environment) often lacks them.
# Both the Python module and the Python-driven tests need "an interpreter
# that has X", so they ask here rather than each searching on its own.
function(hd_find_python out probe)
  set(found "")
  foreach(cand ${ARGN})
    if(cand AND NOT found)
      execute_process(COMMAND ${cand} -c "${probe}" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
      if(rc EQUAL 0)
        set(found ${cand})
      endif()
    endif()
  endforeach()
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

# hd_python3_test(NAME ARG...) -- a test that runs `python3 ARG...` (any
# python3: the standard library only).  Without python3 the configure still
# succeeds (`make run` needs none) and the test fails, saying what to
# install: it is never skipped (`make test` installs python3).
function(hd_python3_test name)
  find_program(HD_PYTHON3 NAMES python3)
  if(HD_PYTHON3)
    add_test(NAME ${name} COMMAND ${HD_PYTHON3} ${ARGN})
  else()
    add_test(NAME ${name} COMMAND sh -c
             "echo '${name}: needs python3 (Debian: python3; scripts/deps.sh test installs it)' >&2; exit 1")
  endif()
endfunction()
