# cmake -DBUILD_DIR=<build> -DJUNIT=<file> -DSTAMP=<file> -P RunTestSuite.cmake
# Runs the whole test suite of BUILD_DIR once (ctest, two jobs, the JUnit file JUNIT) and
# writes STAMP only if every test passed, so a failed suite runs again on the next build.
file(REMOVE ${STAMP})
execute_process(
  COMMAND ${CMAKE_CTEST_COMMAND} --test-dir ${BUILD_DIR} --parallel 2 --output-on-failure
          --no-tests=error --output-junit ${JUNIT}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "railproof: the test suite failed (ctest exit ${rc}); the results are in ${JUNIT}")
endif()
string(TIMESTAMP now "%Y-%m-%dT%H:%M:%SZ" UTC)
file(WRITE ${STAMP} "suite passed ${now}\n")
