# The capability registry (spec/capabilities.yaml) drives the build: at configure time it is
# validated and turned into CMake variables (RAILPROOF_CAPABILITIES, RAILPROOF_CAP_<name>_*)
# and into the seeded-fault identifiers of the mutant-schemata builds. A change to the
# registry re-runs the configure step.
set(RAILPROOF_REGISTRY ${RAILPROOF_SOURCE_DIR}/spec/capabilities.yaml)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
  ${RAILPROOF_REGISTRY} ${RAILPROOF_SOURCE_DIR}/spec/schemas/capabilities.schema.json
  ${RAILPROOF_SOURCE_DIR}/testgen/railproof_testgen/registry.py)
set(_registry_cmake ${RAILPROOF_GEN_DIR}/capabilities.cmake)
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} ${RAILPROOF_PYTHON} -m railproof_testgen registry
          --spec ${RAILPROOF_SOURCE_DIR}/spec --repo ${RAILPROOF_SOURCE_DIR}
          --cmake ${_registry_cmake}
          --faults-header ${RAILPROOF_GEN_DIR}/include/railproof/generated/seeded_faults.hpp
          --json ${RAILPROOF_RESULTS_DIR}/registry.json
  RESULT_VARIABLE _rc ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "railproof: spec/capabilities.yaml: ${_err}")
endif()
include(${_registry_cmake})
