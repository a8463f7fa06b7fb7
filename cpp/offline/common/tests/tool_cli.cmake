# The command line of one offline tool (railproof/offline/cli.hpp), run by ctest:
#   cmake -DTOOL=<executable> -DNAME=<tool name> -P tool_cli.cmake
# --help exits 0 and prints the generated usage line and the footer every tool shares (its own
# exit statuses, then the 2 of bad usage and bad input); an unknown option exits 2 with the
# one-line reason on stderr and nothing on stdout.
execute_process(COMMAND ${TOOL} --help RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "Usage: ${NAME} \\[OPTIONS\\]" OR NOT err STREQUAL ""
   OR NOT out MATCHES "\nExit status: .*;\n2 bad usage or bad input: an input file, or an output that cannot be written\n")
  message(FATAL_ERROR "${NAME} --help: exit ${rc}, stdout:\n${out}\nstderr:\n${err}")
endif()
execute_process(COMMAND ${TOOL} --no-such-option RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(expected "${NAME}: unknown option '--no-such-option' (see --help)\n")
if(NOT rc EQUAL 2 OR NOT err STREQUAL expected OR NOT out STREQUAL "")
  message(FATAL_ERROR "${NAME} --no-such-option: exit ${rc} (expected 2), stderr '${err}' (expected '${expected}')")
endif()
