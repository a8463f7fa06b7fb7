# One run of a conformance runner, checked by ctest:
#   cmake -DRUNNER=<exe> -DPROG=<name> -DDIR=<vector dir> [-DEXTRA=<one more argument>]
#         -DEXIT=<status> -DEXPECT=<regex> -P conformance_expect.cmake
# The run exits with EXIT. A refused run (EXIT not 0) prints exactly one line on stderr,
# "<PROG>: error: <reason>", whose reason EXPECT matches; an accepted set's last line on
# stdout matches EXPECT.
execute_process(COMMAND ${RUNNER} --vectors ${DIR} ${EXTRA} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX REPLACE "\n$" "" last "${out}")
string(REGEX REPLACE ".*\n" "" last "${last}")
set(what "${PROG} --vectors ${DIR} ${EXTRA}: exit ${rc} (expected ${EXIT})\nstderr:\n${err}\nlast line of stdout: ${last}")
if(NOT rc STREQUAL EXIT)
  message(FATAL_ERROR "${what}")
endif()
if(EXIT STREQUAL "0")
  if(NOT last MATCHES "${EXPECT}")
    message(FATAL_ERROR "${what}\nexpected the last line to match: ${EXPECT}")
  endif()
else()
  string(REGEX REPLACE "\n$" "" line "${err}")
  if(line MATCHES "\n" OR NOT line MATCHES "^${PROG}: error: " OR NOT line MATCHES "${EXPECT}")
    message(FATAL_ERROR "${what}\nexpected one line on stderr: ${PROG}: error: ...${EXPECT}")
  endif()
endif()
