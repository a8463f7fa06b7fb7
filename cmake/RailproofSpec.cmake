# spec/ is the single source of truth: it is validated (schemas, duplicates, dangling
# references: testgen validate) and turned into the C++ constants header and the Promela
# #define header before anything else is built. A bad spec entry fails the build with a
# message naming the file and the entry.
set(RAILPROOF_GEN_INCLUDE ${RAILPROOF_GEN_DIR}/include)
file(MAKE_DIRECTORY ${RAILPROOF_GEN_INCLUDE}/railproof/generated ${RAILPROOF_GEN_DIR}/models)
file(GLOB RAILPROOF_SPEC_FILES CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/spec/*.yaml ${RAILPROOF_SOURCE_DIR}/spec/*/*.yaml ${RAILPROOF_SOURCE_DIR}/spec/schemas/*.json)
# The hand-written JSON data of the simulators (spec/scenarios, spec/wheelrail): checked by
# the same validation (schema, then what the schema cannot say), so a bad file fails the
# build naming file, entry and reason; only the validating step depends on them.
file(GLOB RAILPROOF_SPEC_DATA_FILES CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/spec/scenarios/*.json ${RAILPROOF_SOURCE_DIR}/spec/wheelrail/*.json)
# The spec steps depend on the testgen modules they run, not on all of testgen: a change to
# the evidence code does not regenerate the parameter headers (and re-verify every model).
set(_tgm ${RAILPROOF_SOURCE_DIR}/testgen/railproof_testgen)
set(RAILPROOF_SPEC_TOOL_FILES ${_tgm}/__init__.py ${_tgm}/__main__.py ${_tgm}/errors.py ${_tgm}/files.py ${_tgm}/spec.py
    ${_tgm}/checks.py ${_tgm}/validate.py ${_tgm}/lines.py ${_tgm}/trains.py ${_tgm}/timetables.py ${_tgm}/params.py)
# One C++ header and one Promela header per parameter file, named after the file
# (spec/parameters/<name>.yaml -> <name>_params.hpp / .pml; gen-params checks the name).
file(GLOB RAILPROOF_PARAM_FILES CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/parameters/*.yaml)
set(RAILPROOF_PARAM_HEADER)
set(RAILPROOF_PARAM_PML)
foreach(f ${RAILPROOF_PARAM_FILES})
  get_filename_component(n ${f} NAME_WE)
  list(APPEND RAILPROOF_PARAM_HEADER ${RAILPROOF_GEN_INCLUDE}/railproof/generated/${n}_params.hpp)
  list(APPEND RAILPROOF_PARAM_PML ${RAILPROOF_GEN_DIR}/models/${n}_params.pml)
endforeach()
add_custom_command(
  OUTPUT ${RAILPROOF_PARAM_HEADER} ${RAILPROOF_PARAM_PML}
  COMMAND ${RAILPROOF_TESTGEN} gen-params --spec ${RAILPROOF_SOURCE_DIR}/spec --out ${RAILPROOF_GEN_DIR}
  DEPENDS ${RAILPROOF_SPEC_FILES} ${RAILPROOF_SPEC_DATA_FILES} ${RAILPROOF_SPEC_TOOL_FILES}
  COMMENT "spec: validating spec/ and generating parameter headers"
  VERBATIM)
add_custom_target(railproof_gen_params DEPENDS ${RAILPROOF_PARAM_HEADER} ${RAILPROOF_PARAM_PML})

# A converted kind of data (spec/<kind>/*.yaml -> build/gen/<kind>/<name>.json by
# `railproof_testgen <kind>`, which validates first and writes nothing on an error): sets
# RAILPROOF_<VAR>_JSON (the outputs) and the target railproof_gen_<kind>.
function(railproof_spec_data kind var comment)
  file(GLOB _files CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/${kind}/*.yaml)
  set(_json)
  foreach(f ${_files})
    get_filename_component(n ${f} NAME_WE)
    list(APPEND _json ${RAILPROOF_GEN_DIR}/${kind}/${n}.json)
  endforeach()
  add_custom_command(
    OUTPUT ${_json}
    COMMAND ${RAILPROOF_TESTGEN} ${kind} --spec ${RAILPROOF_SOURCE_DIR}/spec --out ${RAILPROOF_GEN_DIR}/${kind}
    DEPENDS ${_files} ${RAILPROOF_SPEC_FILES} ${RAILPROOF_SPEC_TOOL_FILES}
    COMMENT "spec: ${comment}"
    VERBATIM)
  add_custom_target(railproof_gen_${kind} ALL DEPENDS ${_json})
  set(RAILPROOF_${var}_JSON ${_json} PARENT_SCOPE)
endfunction()

# Line data (spec/lines/*.yaml): validated (schema + topology rules, errors name the file
# and entry) and converted to the JSON the C++ line simulator reads (build/gen/lines).
railproof_spec_data(lines LINE "validating spec/lines and writing the line JSON")

# Train types (spec/trains/*.yaml and the negative-test types of spec/trains/mutants):
# validated (schema, ranges, design rule REQ-BR-010) and converted to the JSON read by the
# margin verification and the speed-check design tool (build/gen/trains).
file(GLOB RAILPROOF_TRAIN_FILES CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/trains/*.yaml)
file(GLOB RAILPROOF_TRAIN_MUTANT_FILES CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/trains/mutants/*.yaml)
set(RAILPROOF_TRAIN_JSON)
foreach(f ${RAILPROOF_TRAIN_FILES})
  get_filename_component(n ${f} NAME_WE)
  list(APPEND RAILPROOF_TRAIN_JSON ${RAILPROOF_GEN_DIR}/trains/${n}.json)
endforeach()
set(RAILPROOF_TRAIN_MUTANT_JSON)
foreach(f ${RAILPROOF_TRAIN_MUTANT_FILES})
  get_filename_component(n ${f} NAME_WE)
  list(APPEND RAILPROOF_TRAIN_MUTANT_JSON ${RAILPROOF_GEN_DIR}/trains/mutants/${n}.json)
endforeach()
add_custom_command(
  OUTPUT ${RAILPROOF_TRAIN_JSON} ${RAILPROOF_TRAIN_MUTANT_JSON}
  COMMAND ${RAILPROOF_TESTGEN} trains --spec ${RAILPROOF_SOURCE_DIR}/spec --out ${RAILPROOF_GEN_DIR}/trains
  DEPENDS ${RAILPROOF_TRAIN_FILES} ${RAILPROOF_TRAIN_MUTANT_FILES} ${RAILPROOF_SPEC_FILES} ${RAILPROOF_SPEC_TOOL_FILES}
  COMMENT "spec: validating spec/trains and writing the train JSON"
  VERBATIM)
add_custom_target(railproof_gen_trains ALL DEPENDS ${RAILPROOF_TRAIN_JSON} ${RAILPROOF_TRAIN_MUTANT_JSON})

# Timetables (spec/timetables/*.yaml): validated (schema, then the stations, running lines,
# train types, dwells, platforms and departure order against spec/lines and spec/trains) and
# converted to the JSON read by the level-crossing warning-time study (build/gen/timetables).
railproof_spec_data(timetables TIMETABLE "validating spec/timetables and writing the timetable JSON")
