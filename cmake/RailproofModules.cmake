# One registration call per C++ module, tool and test set (cpp/**/CMakeLists.txt). Every
# target states what it links; the kind of each target (runtime, offline, test) and its
# links are recorded and written to build/gen/targets.json at the end of the configure step,
# where `railproof_testgen layout` checks the module boundaries (a runtime target whose link
# closure reaches an offline target, train-side code linking ground-side code, ...).
#
#   railproof_runtime_module(<name> SOURCES ... [LINKS <module names or imported targets>]
#                            [CAPABILITY <cap>] [SIDE common|onboard|wayside])
#       STATIC library railproof_<name> with include/ PUBLIC; runtime rules (-fno-exceptions,
#       -fno-rtti, warnings as errors). With RAILPROOF_FAULT_BUILDS and a capability whose
#       registry entry has seeded faults, also railproof_<name>_faults: the same sources
#       compiled once with RAILPROOF_SEEDED_FAULTS (mutant schemata: every fault of the module
#       in one test-only variant, selected at run time, spec/design/seeded-faults.md).
#   railproof_offline_module(<name> SOURCES ... [LINKS ...])     STATIC library railproof_<name>
#   railproof_tool(<name> SOURCES ... [LINKS ...])               offline executable <name>
#   railproof_test_set(<name> SOURCES ... [LINKS ...] [RUNTIME] [LABELS ...])
#       GoogleTest executable railproof_<name>_tests, every test case a ctest entry; the test
#       sources are compiled once (OBJECT library). RUNTIME: links runtime modules only, and
#       with faults also railproof_<name>_tests_faults (the same objects against the
#       *_faults variants) for the unit_fault_<F> entries.
#   railproof_conformance(<cap> SOURCES ... [LINKS ...])
#       railproof_conformance_<cap> replaying the pipeline's vectors, its negative tests, and
#       the conformance_fault_<F> entries of the faults the registry says the vectors kill.
#   railproof_bench(SOURCES ... [LINKS ...])                      sources of railproof_bench
#   railproof_input_fuzz_target(<name> SOURCES ... [INCLUDES ...] [LINKS ...] [SEEDS <dir>...]
#                               [SECONDS <s>] [DEFINITIONS ...] [DEPENDS ...] [CAPABILITY <cap>]
#                               [ORACLE_FIRES <seed> <message> ...])
#       fuzz target of an offline tool's input loader (below)

set_property(GLOBAL PROPERTY RAILPROOF_TARGET_KINDS "")

# records a target's kind and its direct links (ARGN) for build/gen/targets.json
function(_railproof_record target kind)
  set_property(GLOBAL APPEND PROPERTY RAILPROOF_TARGET_KINDS "${target}=${kind}")
  set_property(GLOBAL PROPERTY RAILPROOF_LINKS_${target} ${ARGN})
endfunction()

# a module's STATIC library: its folder's include/ and the generated headers PUBLIC, its
# links PUBLIC, the compile options target `options` PRIVATE
function(_railproof_static_library t options)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  add_library(${t} STATIC ${A_SOURCES})
  target_include_directories(${t} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include ${RAILPROOF_GEN_INCLUDE})
  target_link_libraries(${t} PUBLIC ${A_LINKS} PRIVATE ${options})
  add_dependencies(${t} railproof_gen_params)
endfunction()

# a test executable made of the objects of `objs`, linking LINKS (recorded as its links) and
# the test libraries LIBS
function(_railproof_test_executable exe objs kind)
  cmake_parse_arguments(A "" "" "LINKS;LIBS" ${ARGN})
  add_executable(${exe} $<TARGET_OBJECTS:${objs}>)
  target_link_libraries(${exe} PRIVATE ${A_LINKS} ${A_LIBS} railproof_options)
  _railproof_record(${exe} "${kind}" ${A_LINKS})
endfunction()

# each name of ARGN as <prefix><name><suffix> where that target exists, else as it is
function(_railproof_map_targets out prefix suffix)
  set(res)
  foreach(l ${ARGN})
    if(TARGET ${prefix}${l}${suffix})
      list(APPEND res ${prefix}${l}${suffix})
    else()
      list(APPEND res ${l})
    endif()
  endforeach()
  set(${out} ${res} PARENT_SCOPE)
endfunction()

# module names (tg, lc_onboard, offline, ...) become railproof_<name> when that target exists
# (modules are registered before their users); anything else (imported targets, library
# paths and names) stays as it is.
macro(_railproof_resolve out)
  _railproof_map_targets(${out} railproof_ "" ${ARGN})
endmacro()

# the faulty variant of a runtime module if it has one, else the module itself
macro(_railproof_faulty out)
  _railproof_map_targets(${out} "" _faults ${ARGN})
endmacro()

function(_railproof_has_faults cap out)
  set(${out} OFF PARENT_SCOPE)
  if(RAILPROOF_FAULT_BUILDS AND cap AND RAILPROOF_CAP_${cap}_FAULTS)
    set(${out} ON PARENT_SCOPE)
  endif()
endfunction()

function(railproof_runtime_module name)
  cmake_parse_arguments(A "" "CAPABILITY;SIDE" "SOURCES;LINKS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  set(t railproof_${name})
  if(A_SOURCES)
    _railproof_static_library(${t} railproof_runtime_options SOURCES ${A_SOURCES} LINKS ${links})
  else()
    add_library(${t} INTERFACE)
    target_include_directories(${t} INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include ${RAILPROOF_GEN_INCLUDE})
    target_link_libraries(${t} INTERFACE ${links})
    add_dependencies(${t} railproof_gen_params)
  endif()
  set(side ${A_SIDE})
  if(NOT side)
    set(side common)
  endif()
  _railproof_record(${t} "runtime:${side}:${A_CAPABILITY}" ${links})
  # the schemata variant exists only for modules that hold fault sites; the others are linked
  # as they are
  _railproof_has_faults("${A_CAPABILITY}" faults)
  set(sites OFF)
  foreach(src ${A_SOURCES})
    file(STRINGS ${CMAKE_CURRENT_SOURCE_DIR}/${src} hit REGEX "RAILPROOF_FAULT\\(")
    if(hit)
      set(sites ON)
    endif()
  endforeach()
  if(A_SOURCES)
    # the production build holds no seeded fault: no selector is linked into it
    add_test(NAME no_seeded_fault_in_${t} COMMAND ${CMAKE_NM} -C $<TARGET_FILE:${t}>)
    set_tests_properties(no_seeded_fault_in_${t} PROPERTIES LABELS "seeded_fault;layout"
      FAIL_REGULAR_EXPRESSION "SeededFault")
  endif()
  if(faults AND sites)
    _railproof_faulty(flinks ${links})
    _railproof_static_library(${t}_faults railproof_runtime_options SOURCES ${A_SOURCES}
                              LINKS ${flinks} railproof_seeded_faults)
    target_compile_definitions(${t}_faults PRIVATE RAILPROOF_SEEDED_FAULTS)
    _railproof_record(${t}_faults "test:schemata:${A_CAPABILITY}" ${flinks} railproof_seeded_faults)
    # ... and the check above can see a selector: the schemata variant has one
    add_test(NAME seeded_fault_selector_in_${t}_faults COMMAND ${CMAKE_NM} -C $<TARGET_FILE:${t}_faults>)
    set_tests_properties(seeded_fault_selector_in_${t}_faults PROPERTIES LABELS "seeded_fault;layout"
      PASS_REGULAR_EXPRESSION "SeededFaultActive")
  endif()
endfunction()

function(railproof_offline_module name)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  _railproof_static_library(railproof_${name} railproof_options SOURCES ${A_SOURCES} LINKS ${links})
  _railproof_record(railproof_${name} "offline" ${links})
endfunction()

function(railproof_tool name)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE ${links} railproof_options)
  _railproof_record(${name} "offline" ${links})
endfunction()

# A test driver's objects reuse the test drivers' precompiled header (cpp/testing/CMakeLists.txt).
function(_railproof_test_pch objs)
  if(RAILPROOF_TEST_PCH)
    target_precompile_headers(${objs} REUSE_FROM railproof_test_pch)
  endif()
endfunction()

function(railproof_test_set name)
  cmake_parse_arguments(A "RUNTIME" "CAPABILITY" "SOURCES;LINKS;LABELS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  set(objs railproof_${name}_test_objects)
  add_library(${objs} OBJECT ${A_SOURCES})
  # the test objects see the headers of what they test (and GoogleTest); they are compiled once
  target_link_libraries(${objs} PRIVATE ${links} railproof_testing GTest::gtest railproof_options
                        railproof_test_driver_options)
  _railproof_test_pch(${objs})
  add_dependencies(${objs} railproof_gen_lines railproof_gen_trains railproof_gen_timetables)
  set(exe railproof_${name}_tests)
  if(A_RUNTIME)
    set(kind "test:runtime:${A_CAPABILITY}")
  else()
    set(kind "test:offline:${A_CAPABILITY}")
  endif()
  _railproof_test_executable(${exe} ${objs} "${kind}" LINKS ${links} LIBS railproof_testing GTest::gtest_main)
  set(labels unit ${A_LABELS})
  if(A_CAPABILITY)
    list(APPEND labels ${A_CAPABILITY})
  endif()
  gtest_discover_tests(${exe}
    TEST_PREFIX "${name}."
    XML_OUTPUT_DIR ${RAILPROOF_RESULTS_DIR}/tests/unit/${name}
    PROPERTIES LABELS "${labels}"
    DISCOVERY_TIMEOUT 60)
  _railproof_has_faults("${A_CAPABILITY}" faults)
  if(A_RUNTIME AND faults)
    _railproof_faulty(flinks ${links})
    set(fexe ${exe}_faults)
    _railproof_test_executable(${fexe} ${objs} "test:schemata:${A_CAPABILITY}"
                               LINKS ${flinks} LIBS railproof_testing GTest::gtest_main)
    foreach(fault ${RAILPROOF_CAP_${A_CAPABILITY}_FAULTS_UNIT})
      add_test(NAME unit_fault_${fault} COMMAND ${fexe}
               --gtest_output=xml:${RAILPROOF_RESULTS_DIR}/tests/faults/unit_${fault}.xml)
      set_tests_properties(unit_fault_${fault} PROPERTIES
        LABELS "seeded_fault;${A_CAPABILITY}" ENVIRONMENT "RAILPROOF_SEEDED_FAULT=${fault}"
        PASS_REGULAR_EXPRESSION "\\[  FAILED  \\] [1-9][0-9]* tests?, listed below")
    endforeach()
    # the schemata build with no fault selected behaves as the production build
    add_test(NAME unit_faults_none_selected_${A_CAPABILITY} COMMAND ${fexe})
    set_tests_properties(unit_faults_none_selected_${A_CAPABILITY} PROPERTIES LABELS "seeded_fault;${A_CAPABILITY}")
  endif()
endfunction()

function(railproof_conformance cap)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  set(libs railproof_testing GTest::gtest nlohmann_json::nlohmann_json)
  set(objs railproof_conformance_${cap}_objects)
  add_library(${objs} OBJECT ${A_SOURCES})
  target_link_libraries(${objs} PRIVATE ${links} ${libs} railproof_options railproof_test_driver_options)
  _railproof_test_pch(${objs})
  set(exe railproof_conformance_${cap})
  _railproof_test_executable(${exe} ${objs} "test:runtime:${cap}" LINKS ${links} LIBS ${libs})
  set(prog "railproof-conformance-${cap}")
  add_test(NAME conformance_${cap}
           COMMAND ${exe} --vectors ${RAILPROOF_CONFORMANCE_VECTORS}
                   --gtest_output=xml:${RAILPROOF_RESULTS_DIR}/tests/conformance/${cap}.xml)
  set_tests_properties(conformance_${cap} PROPERTIES LABELS "conformance;${cap}")
  add_test(NAME conformance_${cap}_rejects_missing_dir
           COMMAND ${exe} --vectors ${CMAKE_CURRENT_BINARY_DIR}/no_such_dir)
  add_test(NAME conformance_${cap}_rejects_empty_dir
           COMMAND ${exe} --vectors ${RAILPROOF_EMPTY_VECTOR_DIR})
  set_tests_properties(conformance_${cap}_rejects_missing_dir PROPERTIES LABELS "conformance;${cap}"
    PASS_REGULAR_EXPRESSION "${prog}: error: vector directory .* does not exist")
  set_tests_properties(conformance_${cap}_rejects_empty_dir PROPERTIES LABELS "conformance;${cap}"
    PASS_REGULAR_EXPRESSION "${prog}: error: no \\*\\.jsonl vector file")
  # A test report that cannot be written (its directory is a file) is refused before the run.
  set(expect_script ${RAILPROOF_SOURCE_DIR}/cpp/testing/conformance_expect.cmake)
  add_test(NAME conformance_${cap}_rejects_unwritable_report
           COMMAND ${CMAKE_COMMAND} -DRUNNER=$<TARGET_FILE:${exe}> -DPROG=${prog} -DDIR=${RAILPROOF_EMPTY_VECTOR_DIR}
                   -DEXTRA=--junit=${CMAKE_CURRENT_LIST_FILE}/report.xml -DEXIT=2
                   "-DEXPECT=cannot write the test report .*/report.xml: Not a directory$" -P ${expect_script})
  set_tests_properties(conformance_${cap}_rejects_unwritable_report PROPERTIES LABELS "conformance;${cap}")
  # Small sets made from the build's vectors (cpp/testing/damaged_vector_sets.py): the whole
  # one passes, each damaged one is refused with exit 1 and its one-line reason.
  set(damaged ${CMAKE_CURRENT_BINARY_DIR}/damaged_vector_sets)
  add_test(NAME conformance_${cap}_damaged_sets
           COMMAND ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} ${RAILPROOF_PYTHON}
                   ${RAILPROOF_SOURCE_DIR}/cpp/testing/damaged_vector_sets.py
                   --vectors ${RAILPROOF_CONFORMANCE_VECTORS} --prefix ${cap} --out ${damaged})
  set_tests_properties(conformance_${cap}_damaged_sets PROPERTIES LABELS "conformance;${cap}"
    FIXTURES_SETUP conformance_${cap}_damaged)
  set(file "${cap}\\.jsonl")
  foreach(case_expect
      "whole|0|${prog}: all 2 vectors passed \\(2 in the set\\)"
      "truncated|1|${file}:1: the header states 2 vectors, the file has 1$"
      "changed_vector|1|${file}:1: the vector lines do not match the header.s vectors_sha256"
      "schema_version|1|${file}:1: schema_version 1 is not supported \\(expected 2\\)$"
      "unknown_header_key|1|${file}:1: unknown header key .unknown_field.$"
      "unknown_step_key|1|${file}:2: unknown key .steps\\[0\\]\\.(in\\.)?unknown_input.$"
      "duplicate_key|1|${file}:2: duplicate key .steps\\[0\\]\\.[^ ]+$"
      "empty_file|1|${file}:1: empty file \\(no header line\\)$"
      "bad_header|1|${file}:1: malformed JSON: ")
    string(REPLACE "|" ";" parts "${case_expect}")
    list(GET parts 0 case)
    list(GET parts 1 status)
    list(GET parts 2 expect)
    set(name conformance_${cap}_rejects_${case})
    if(case STREQUAL "whole")
      set(name conformance_${cap}_accepts_whole_small_set)
    endif()
    add_test(NAME ${name}
             COMMAND ${CMAKE_COMMAND} -DRUNNER=$<TARGET_FILE:${exe}> -DPROG=${prog} -DDIR=${damaged}/${case}
                     -DEXIT=${status} "-DEXPECT=${expect}" -P ${expect_script})
    set_tests_properties(${name} PROPERTIES LABELS "conformance;${cap}" FIXTURES_REQUIRED conformance_${cap}_damaged)
  endforeach()
  _railproof_has_faults("${cap}" faults)
  if(faults)
    _railproof_faulty(flinks ${links})
    set(fexe ${exe}_faults)
    _railproof_test_executable(${fexe} ${objs} "test:schemata:${cap}" LINKS ${flinks} LIBS ${libs})
    foreach(fault ${RAILPROOF_CAP_${cap}_FAULTS_VECTORS})
      add_test(NAME conformance_fault_${fault}
               COMMAND ${fexe} --vectors ${RAILPROOF_CONFORMANCE_VECTORS}
                       --gtest_output=xml:${RAILPROOF_RESULTS_DIR}/tests/faults/conformance_${fault}.xml)
      set_tests_properties(conformance_fault_${fault} PROPERTIES
        LABELS "conformance;seeded_fault;${cap}" ENVIRONMENT "RAILPROOF_SEEDED_FAULT=${fault}"
        PASS_REGULAR_EXPRESSION "${prog}: vectors mismatched: [1-9][0-9]* of")
    endforeach()
    add_test(NAME conformance_faults_none_selected_${cap}
             COMMAND ${fexe} --vectors ${RAILPROOF_CONFORMANCE_VECTORS})
    set_tests_properties(conformance_faults_none_selected_${cap} PROPERTIES
      LABELS "conformance;seeded_fault;${cap}" PASS_REGULAR_EXPRESSION "${prog}: all [0-9]+ vectors passed")
  endif()
endfunction()

function(railproof_bench)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  if(NOT RAILPROOF_BENCH)
    return()
  endif()
  _railproof_resolve(links ${A_LINKS})
  set_property(GLOBAL APPEND PROPERTY RAILPROOF_BENCH_SOURCES ${A_SOURCES})
  set_property(GLOBAL APPEND PROPERTY RAILPROOF_BENCH_LINKS ${links})
endfunction()

# railproof_input_fuzz_target(<name> SOURCES ... [INCLUDES ...] [LINKS ...] [SEEDS <dir>...]
#                             [SECONDS <s>] [DEFINITIONS ...] [DEPENDS ...] [CAPABILITY <cap>]
#                             [ORACLE_FIRES <seed> <message> ...])
#   The fuzz target of an offline tool's input loader (cpp/offline/<module>/fuzz, spec/design/
#   data.md §2): SOURCES are the target's file and the loader's sources, compiled into one
#   executable with the shared harness (cpp/offline/common/fuzz/json_fuzz.hpp); INCLUDES the
#   include folders of those sources (the offline modules are not linked: their loaders are the
#   instrumented sources; the loaders of offline/common that several targets read, the JSON
#   reader, the line and the train type, come instrumented once from fuzz_loaders, see
#   railproof_fuzz_library), LINKS the runtime modules and libraries it needs (uninstrumented);
#   DEPENDS the targets that make its data. Its seeds are the committed corpus fuzz/corpus/<name without fuzz_>/ of the calling
#   folder and the SEEDS folders (read only: the data the loader is made for).
#   With RAILPROOF_FUZZ (clang): a libFuzzer executable with coverage and ASan+UBSan, and the
#   ctest entries (label fuzz) <name>_seeds, every seed once, and <name>_<s>s, s seconds of
#   fuzzing (default 20) whose new inputs go to a build folder emptied first
#   (<name>_work_reset). Without it (the g++ ASan+UBSan preset): <name>_replay, which runs
#   every seed once under the build's sanitizers (ctest <name>_corpus_replay, label
#   fuzz_replay; replay_main.cpp of the telegram fuzz targets). A longer run:
#     build/cpp/offline/<module>/<name> -max_total_time=3600 -timeout=10 <new inputs dir> <seeds>
#   ORACLE_FIRES makes a negative test of the oracle instead (libFuzzer builds): for each
#   committed seed named, the entry <name>_<seed without .json> passes when the oracle fires on
#   it with the message "railproof-fuzz: oracle violated: <message>" (a regular expression).
# railproof_fuzz_library(<name> SOURCES ... LINKS ...): a static library railproof_<name> of
#   loader sources several fuzz targets share, compiled once with the fuzz targets' flags (with
#   RAILPROOF_FUZZ: coverage instrumentation without libFuzzer's main, ASan+UBSan; otherwise
#   the build's flags), instead of once per target.
function(railproof_fuzz_library name)
  cmake_parse_arguments(A "" "" "SOURCES;LINKS" ${ARGN})
  _railproof_resolve(links ${A_LINKS})
  _railproof_static_library(railproof_${name} railproof_options SOURCES ${A_SOURCES} LINKS ${links})
  if(RAILPROOF_FUZZ)
    target_compile_options(railproof_${name} PRIVATE ${RAILPROOF_FUZZ_LIBRARY_FLAGS})
  endif()
  _railproof_record(railproof_${name} "offline" ${links})
endfunction()

function(railproof_input_fuzz_target name)
  cmake_parse_arguments(A "" "SECONDS;CAPABILITY" "SOURCES;INCLUDES;LINKS;SEEDS;DEFINITIONS;DEPENDS;ORACLE_FIRES" ${ARGN})
  if(NOT A_SECONDS)
    set(A_SECONDS 20)
  endif()
  _railproof_resolve(links ${A_LINKS})
  string(REGEX REPLACE "^fuzz_" "" corpus ${name})
  set(seeds ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/${corpus} ${A_SEEDS})
  if(RAILPROOF_FUZZ)
    set(exe ${name})
    add_executable(${exe} ${A_SOURCES})
    target_compile_options(${exe} PRIVATE ${RAILPROOF_FUZZ_TARGET_FLAGS})
    target_link_options(${exe} PRIVATE ${RAILPROOF_FUZZ_LINK_FLAGS})
  else()
    set(exe ${name}_replay)
    add_executable(${exe} ${A_SOURCES} ${RAILPROOF_SOURCE_DIR}/cpp/runtime/tg/fuzz/replay_main.cpp)
  endif()
  target_include_directories(${exe} PRIVATE ${A_INCLUDES} ${RAILPROOF_SOURCE_DIR}/cpp/offline/common/include
                             ${RAILPROOF_SOURCE_DIR}/cpp/offline/common/fuzz ${RAILPROOF_GEN_INCLUDE})
  target_compile_definitions(${exe} PRIVATE ${A_DEFINITIONS})
  target_link_libraries(${exe} PRIVATE ${links} railproof_options)
  add_dependencies(${exe} railproof_gen_params ${A_DEPENDS})
  _railproof_record(${exe} "test:offline:${A_CAPABILITY}" ${links})
  if(A_ORACLE_FIRES)
    if(NOT RAILPROOF_FUZZ)
      return()  # a trap without libFuzzer's handler is a crash to ctest, whatever it printed
    endif()
    while(A_ORACLE_FIRES)
      list(POP_FRONT A_ORACLE_FIRES seed message)
      string(REGEX REPLACE "\\.json$" "" test ${name}_${seed})
      add_test(NAME ${test} COMMAND ${exe} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/${corpus}/${seed})
      set_tests_properties(${test} PROPERTIES LABELS fuzz TIMEOUT 60
        PASS_REGULAR_EXPRESSION "railproof-fuzz: oracle violated: ${message}")
    endwhile()
    return()
  endif()
  if(NOT RAILPROOF_FUZZ)
    add_test(NAME ${name}_corpus_replay COMMAND ${exe} ${seeds})
    set_tests_properties(${name}_corpus_replay PROPERTIES LABELS fuzz_replay
      PASS_REGULAR_EXPRESSION "railproof-fuzz-replay: [1-9][0-9]* inputs")
    return()
  endif()
  set(work ${CMAKE_CURRENT_BINARY_DIR}/fuzz/work/${corpus})
  set(artifacts ${CMAKE_CURRENT_BINARY_DIR}/fuzz/artifacts/${corpus})
  file(MAKE_DIRECTORY ${artifacts})
  add_test(NAME ${name}_work_reset COMMAND ${CMAKE_COMMAND} -E rm -rf ${work})
  set_tests_properties(${name}_work_reset PROPERTIES LABELS fuzz FIXTURES_SETUP ${name}_work)
  add_test(NAME ${name}_seeds COMMAND ${exe} -runs=0 -timeout=10 -artifact_prefix=${artifacts}/ ${seeds})
  add_test(NAME ${name}_${A_SECONDS}s
           COMMAND ${exe} -max_total_time=${A_SECONDS} -timeout=10 -print_final_stats=1 -create_missing_dirs=1
                   -artifact_prefix=${artifacts}/ ${work} ${seeds})
  math(EXPR timeout "${A_SECONDS} * 3 + 60")
  set_tests_properties(${name}_seeds ${name}_${A_SECONDS}s PROPERTIES LABELS fuzz TIMEOUT ${timeout})
  set_tests_properties(${name}_${A_SECONDS}s PROPERTIES FIXTURES_REQUIRED ${name}_work)
endfunction()

# build/gen/targets.json: every registered target with its kind and direct links.
function(railproof_write_targets file)
  get_property(kinds GLOBAL PROPERTY RAILPROOF_TARGET_KINDS)
  set(json "{\n  \"schema\": \"railproof/targets/1\",\n  \"targets\": {")
  set(sep "")
  foreach(entry ${kinds})
    string(REPLACE "=" ";" kv "${entry}")
    list(GET kv 0 t)
    list(GET kv 1 kind)
    get_property(deps GLOBAL PROPERTY RAILPROOF_LINKS_${t})
    string(REPLACE ";" "\", \"" deps_json "${deps}")
    if(deps_json)
      set(deps_json "\"${deps_json}\"")
    endif()
    string(APPEND json "${sep}\n    \"${t}\": {\"kind\": \"${kind}\", \"links\": [${deps_json}]}")
    set(sep ",")
  endforeach()
  string(APPEND json "\n  }\n}\n")
  file(WRITE ${file}.tmp "${json}")
  file(COPY_FILE ${file}.tmp ${file} ONLY_IF_DIFFERENT)
  file(REMOVE ${file}.tmp)
endfunction()

# railproof_study(<name> OUTPUTS <first is the result JSON> ... COMMAND ... DEPENDS ... [COMMENT ...])
#   A pipeline step of the capability's offline analyses: its result feeds the trace and the
#   evidence. The folder that builds the tool declares it; the pipeline (top-level directory,
#   where the trace and the evidence can depend on its outputs) adds the build step. It runs
#   in parallel with every step it does not depend on.
function(railproof_study name)
  cmake_parse_arguments(A "" "COMMENT" "OUTPUTS;COMMAND;DEPENDS" ${ARGN})
  if(NOT A_COMMENT)
    set(A_COMMENT "study: ${name}")
  endif()
  set_property(GLOBAL APPEND PROPERTY RAILPROOF_STUDIES ${name})
  set_property(GLOBAL PROPERTY RAILPROOF_STUDY_${name}_OUTPUTS ${A_OUTPUTS})
  set_property(GLOBAL PROPERTY RAILPROOF_STUDY_${name}_COMMAND ${A_COMMAND})
  set_property(GLOBAL PROPERTY RAILPROOF_STUDY_${name}_DEPENDS ${A_DEPENDS})
  set_property(GLOBAL PROPERTY RAILPROOF_STUDY_${name}_COMMENT "${A_COMMENT}")
endfunction()
