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
