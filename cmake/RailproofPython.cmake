# Python tooling (testgen, evidence) runs from a virtual environment under the build
# directory with the pinned versions of testgen/requirements.txt. It is created at
# configure time if missing or if the requirements changed.
find_package(Python3 3.9 REQUIRED COMPONENTS Interpreter)
set(RAILPROOF_VENV ${CMAKE_BINARY_DIR}/venv)
set(RAILPROOF_PYTHON ${RAILPROOF_VENV}/bin/python)
set(_req ${RAILPROOF_SOURCE_DIR}/testgen/requirements.txt)
file(SHA256 ${_req} _req_hash)
set(_stamp ${RAILPROOF_VENV}/.railproof-requirements.sha256)
set(_have "")
if(EXISTS ${_stamp})
  file(READ ${_stamp} _have)
endif()
if(NOT EXISTS ${RAILPROOF_PYTHON} OR NOT _have STREQUAL _req_hash)
  message(STATUS "railproof: creating Python environment ${RAILPROOF_VENV}")
  execute_process(COMMAND ${Python3_EXECUTABLE} -m venv ${RAILPROOF_VENV} RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "railproof: cannot create venv (is python3-venv installed?)")
  endif()
  execute_process(COMMAND ${RAILPROOF_PYTHON} -m pip install --quiet --disable-pip-version-check
                          -r ${_req} RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "railproof: pip install -r ${_req} failed")
  endif()
  file(WRITE ${_stamp} ${_req_hash})
endif()
# testgen is used from the source tree (no install step): PYTHONPATH points at it.
set(RAILPROOF_PY_ENV PYTHONPATH=${RAILPROOF_SOURCE_DIR}/testgen PYTHONDONTWRITEBYTECODE=1)
set(RAILPROOF_TESTGEN ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} ${RAILPROOF_PYTHON} -m railproof_testgen)
