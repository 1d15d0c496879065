# Runs glint-render with ARGS and checks it exited 0 (validation clean) and
# logged the environment's prefilter (EXPECT, a regular expression).
execute_process(COMMAND ${RENDER} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-render exited with ${rc}")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "glint-render did not log '${EXPECT}'")
endif()
