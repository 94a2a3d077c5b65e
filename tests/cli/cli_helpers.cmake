# Helpers of the command-line tests (included by tests/cli/*.cmake; FARFIELD names the farfield binary).

# run_ok(COMMAND...): runs a command that must exit 0; its stdout is left in LAST_OUT.
function(run_ok)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN}: exit code ${rc}\nstdout: ${out}\nstderr: ${err}")
  endif()
  set(LAST_OUT "${out}" PARENT_SCOPE)
endfunction()

# expect_error(SUBSTRING ARGS...): `farfield ARGS...` must exit 2 with "error: " and SUBSTRING on stderr.
function(expect_error expected_substring)
  execute_process(COMMAND ${FARFIELD} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2)
    message(FATAL_ERROR "farfield ${ARGN}: expected exit code 2, got '${rc}'\nstdout: ${out}\nstderr: ${err}")
  endif()
  if(NOT err MATCHES "error: ")
    message(FATAL_ERROR "farfield ${ARGN}: stderr lacks 'error: '\n${err}")
  endif()
  string(FIND "${err}" "${expected_substring}" pos)
  if(pos EQUAL -1)
    message(FATAL_ERROR "farfield ${ARGN}: stderr lacks '${expected_substring}'\n${err}")
  endif()
  message(STATUS "ok: farfield ${ARGN} -> ${err}")
endfunction()
