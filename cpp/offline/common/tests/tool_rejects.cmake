# Bad input of one offline tool, run as a process by ctest (railproof_tool_rejects):
#   cmake -DSCRATCH=<dir> -DEXPECT=<stderr line> -DCOMMAND=<tool;arg;...> -P tool_rejects.cmake
# The tool runs in SCRATCH, made afresh with a regular file `blocker` (an output path below it
# cannot be made) and a previous result kept/result.json. It must exit with status 2 and
# print exactly the line EXPECT on stderr, and write nothing: afterwards SCRATCH holds the
# same two files, unchanged, and nothing else (no result, no temporary file, no directory).
file(REMOVE_RECURSE ${SCRATCH})
file(MAKE_DIRECTORY ${SCRATCH}/kept)
file(WRITE ${SCRATCH}/blocker "blocker\n")
file(WRITE ${SCRATCH}/kept/result.json "previous result\n")
execute_process(COMMAND ${COMMAND} WORKING_DIRECTORY ${SCRATCH}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(problems)
if(NOT rc STREQUAL "2")
  list(APPEND problems "exit status ${rc}, expected 2")
endif()
if(NOT err STREQUAL "${EXPECT}\n")
  list(APPEND problems "stderr '${err}', expected the one line '${EXPECT}'")
endif()
file(GLOB_RECURSE left RELATIVE ${SCRATCH} LIST_DIRECTORIES true ${SCRATCH}/*)
list(SORT left)
if(NOT left STREQUAL "blocker;kept;kept/result.json")
  list(APPEND problems "written: the scratch folder holds '${left}'")
endif()
file(READ ${SCRATCH}/kept/result.json kept)
if(NOT kept STREQUAL "previous result\n")
  list(APPEND problems "the previous result was changed to '${kept}'")
endif()
if(problems)
  string(REPLACE ";" "\n  " problems "${problems}")
  message(FATAL_ERROR "${COMMAND}:\n  ${problems}")
endif()
file(REMOVE_RECURSE ${SCRATCH})
