# cmake -DPROGRAM=path -DEXPECT=regex [-DARGS=a;b] -P run_expecting.cmake
# Runs PROGRAM and passes only when it exits 0 AND its standard output matches EXPECT (ctest's
# PASS_REGULAR_EXPRESSION alone ignores the exit status, so a crash after the expected line would
# pass). Prints the program's output either way.
execute_process(COMMAND ${PROGRAM} ${ARGS} RESULT_VARIABLE status OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
message("${out}${err}")
if(NOT status STREQUAL "0")
  message(FATAL_ERROR "${PROGRAM} exited with ${status}, expected 0")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "${PROGRAM}: output does not match \"${EXPECT}\"")
endif()
