# Runs `psysc check NAME.psys` in DIR and compares its diagnostics with NAME.err.
# A case passes when psysc prints exactly the expected text and exits 1 (0 when the
# expected text holds only warnings).
execute_process(
  COMMAND ${PSYSC} check --color=never ${NAME}.psys
  WORKING_DIRECTORY ${DIR}
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
file(READ ${DIR}/${NAME}.err expected)
file(MAKE_DIRECTORY ${OUT})
file(WRITE ${OUT}/${NAME}.actual "${err}")
set(expected_rc 0)
if(expected MATCHES ": error: ")
  set(expected_rc 1)
endif()
if(NOT rc EQUAL expected_rc)
  message(FATAL_ERROR "psysc exited with ${rc}, expected ${expected_rc}\n${err}")
endif()
if(NOT err STREQUAL expected)
  message(FATAL_ERROR "diagnostics differ from ${NAME}.err\n--- expected\n${expected}--- actual (${OUT}/${NAME}.actual)\n${err}")
endif()
