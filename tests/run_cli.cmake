# Runs psysc with ARGS (separated by |), expects exit code EXPECT_RC and output (stdout and
# stderr together) matching the regular expression EXPECT.
string(REPLACE "|" ";" ARGS "${ARGS}")
execute_process(COMMAND ${PSYSC} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(all "${out}${err}")
if(NOT rc EQUAL EXPECT_RC)
  message(FATAL_ERROR "psysc ${ARGS}: exit code ${rc}, expected ${EXPECT_RC}\n${all}")
endif()
if(NOT all MATCHES "${EXPECT}")
  message(FATAL_ERROR "psysc ${ARGS}: output does not match `${EXPECT}`\n${all}")
endif()
