# Runs `psc GAME --emit ir --format reference` and compares it byte for byte with EXPECTED.
execute_process(COMMAND ${PSC} ${GAME} --emit ir --format reference
                OUTPUT_VARIABLE actual RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "psc failed (${rc}): ${err}")
endif()
file(READ ${EXPECTED} expected)
if(NOT actual STREQUAL expected)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/actual.json "${actual}")
  message(FATAL_ERROR "psc's IR of ${GAME} differs from ${EXPECTED}; psc's is in ${CMAKE_CURRENT_BINARY_DIR}/actual.json")
endif()
