# Runs `psysc check NAME.psys` in DIR and compares its diagnostics with NAME.err.
# A case passes when psysc exits 1 and prints exactly the expected text.
execute_process(
  COMMAND ${PSYSC} check --color=never ${NAME}.psys
  WORKING_DIRECTORY ${DIR}
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
file(READ ${DIR}/${NAME}.err expected)
file(MAKE_DIRECTORY ${OUT})
file(WRITE ${OUT}/${NAME}.actual "${err}")
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "psysc exited with ${rc}, expected 1\n${err}")
endif()
if(NOT err STREQUAL expected)
  message(FATAL_ERROR "diagnostics differ from ${NAME}.err\n--- expected\n${expected}--- actual (${OUT}/${NAME}.actual)\n${err}")
endif()
