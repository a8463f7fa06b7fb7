# The evidence pipeline (conventions §1): model checking -> vectors -> conformance ->
# traceability -> evidence. Every step is a build product with its inputs as
# dependencies, so a second run with nothing changed does nothing.
#
#   ALL       : SPIN verification of every property and mutant (fails on any violation,
#               printing the counterexample), vector generation with goal coverage.
#   evidence  : test results as JUnit XML (unit, conformance, testgen), residual-error
#               analysis, tool versions, trace.json, and the rendered evidence package
#               in ${CMAKE_BINARY_DIR}/evidence (HTML + manifest.json with SHA-256).
set(RAILPROOF_MODELS telegram moving_block braking readhesion level_crossing)
set(RAILPROOF_VECTOR_DIR ${RAILPROOF_RESULTS_DIR}/vectors)
set(_spin_outputs)
set(_vector_outputs)
foreach(model ${RAILPROOF_MODELS})
  set(_pml ${RAILPROOF_SOURCE_DIR}/models/${model}.pml)
  set(_spin_json ${RAILPROOF_RESULTS_DIR}/spin/${model}.json)
  add_custom_command(
    OUTPUT ${_spin_json}
    COMMAND ${RAILPROOF_TESTGEN} verify --model ${_pml} --params ${RAILPROOF_GEN_DIR}/models
            --work ${CMAKE_BINARY_DIR}/spin/${model}/verify --out ${_spin_json}
    DEPENDS ${_pml} ${RAILPROOF_GEN_DIR}/models/${model}_params.pml ${RAILPROOF_TESTGEN_FILES}
    COMMENT "SPIN: exhaustive verification of models/${model}.pml (properties, mutants)"
    USES_TERMINAL VERBATIM)
  set(_vec ${RAILPROOF_VECTOR_DIR}/${model}.jsonl)
  add_custom_command(
    OUTPUT ${_vec} ${RAILPROOF_VECTOR_DIR}/${model}.coverage.json
    COMMAND ${RAILPROOF_TESTGEN} vectors --model ${_pml} --params ${RAILPROOF_GEN_DIR}/models
            --spec ${RAILPROOF_SOURCE_DIR}/spec --work ${CMAKE_BINARY_DIR}/spin/${model}/vectors
            --out ${RAILPROOF_VECTOR_DIR}
    DEPENDS ${_spin_json} ${RAILPROOF_SPEC_FILES}
    COMMENT "testgen: trap, boundary and random-walk vectors from models/${model}.pml"
    USES_TERMINAL VERBATIM)
  list(APPEND _spin_outputs ${_spin_json})
  list(APPEND _vector_outputs ${_vec})
endforeach()
add_custom_target(railproof_models ALL DEPENDS ${_spin_outputs} ${_vector_outputs})

# ---- evidence inputs that come from running things ------------------------------------
set(_tests_dir ${RAILPROOF_RESULTS_DIR}/tests)
file(GLOB_RECURSE _pytests CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/tests/*.py)
add_custom_command(
  OUTPUT ${_tests_dir}/unit.xml
  COMMAND ${CMAKE_COMMAND} -E make_directory ${_tests_dir}
  COMMAND railproof_unit_tests --gtest_output=xml:${_tests_dir}/unit.xml
  DEPENDS railproof_unit_tests
  COMMENT "tests: C++ unit tests -> results/tests/unit.xml" USES_TERMINAL VERBATIM)
set(_evidence_tests ${_tests_dir}/unit.xml)
# Conformance replays: one JUnit file per runner (railproof_conformance = telegram, _mb =
# moving block, _br = braking decision, _ra = re-adhesion state machine, _lc = level crossings).
foreach(_conf conformance conformance_mb conformance_br conformance_ra conformance_lc)
  if(TARGET railproof_${_conf})
    add_custom_command(
      OUTPUT ${_tests_dir}/${_conf}.xml
      COMMAND ${CMAKE_COMMAND} -E make_directory ${_tests_dir}
      COMMAND railproof_${_conf} --vectors ${RAILPROOF_VECTOR_DIR}
              --gtest_output=xml:${_tests_dir}/${_conf}.xml
      DEPENDS railproof_${_conf} ${_vector_outputs}
      COMMENT "tests: ${_conf} replay of the vectors -> results/tests/${_conf}.xml"
      USES_TERMINAL VERBATIM)
    list(APPEND _evidence_tests ${_tests_dir}/${_conf}.xml)
  endif()
endforeach()
add_custom_command(
  OUTPUT ${_tests_dir}/testgen.xml
  COMMAND ${CMAKE_COMMAND} -E make_directory ${_tests_dir}
  COMMAND ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} ${RAILPROOF_PYTHON} -m pytest -q -p no:cacheprovider
          ${RAILPROOF_SOURCE_DIR}/testgen/tests --junitxml=${_tests_dir}/testgen.xml
  DEPENDS ${_pytests} ${RAILPROOF_TESTGEN_FILES}
  COMMENT "tests: testgen (pytest) -> results/tests/testgen.xml" USES_TERMINAL VERBATIM)
list(APPEND _evidence_tests ${_tests_dir}/testgen.xml)

set(_residual ${RAILPROOF_RESULTS_DIR}/analysis/residual_error.json)
add_custom_command(
  OUTPUT ${_residual}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/analysis
  COMMAND residual_error --json ${_residual}  # bit error rates from spec/parameters
  DEPENDS residual_error
  COMMENT "analysis: residual error rate of RS(66,50)+CRC-16+MAC" VERBATIM)

# Line scenarios (spec/scenarios/*.json): the C++ ground and on-board units, train dynamics
# and the telegram layer over a lossy channel, with faults; every safety invariant checked
# at every step (line_sim exits non-zero on any violation). Summaries (with the
# requirements they evidence) go to results/analysis, logs and diagrams to results/scenarios.
set(_scenario_outputs)
if(TARGET line_sim)
  file(GLOB _scenarios CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/scenarios/*.json)
  foreach(sc ${_scenarios})
    get_filename_component(n ${sc} NAME_WE)
    set(_sum ${RAILPROOF_RESULTS_DIR}/analysis/scenario_${n}.json)
    add_custom_command(
      OUTPUT ${_sum} ${RAILPROOF_RESULTS_DIR}/scenarios/${n}.svg
      COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/scenarios ${RAILPROOF_RESULTS_DIR}/analysis
      COMMAND line_sim --scenario ${sc} --lines-dir ${RAILPROOF_GEN_DIR}/lines --quiet
              --log ${RAILPROOF_RESULTS_DIR}/scenarios/${n}.log.json
              --svg ${RAILPROOF_RESULTS_DIR}/scenarios/${n}.svg --summary ${_sum}
      DEPENDS line_sim ${sc} ${RAILPROOF_LINE_JSON}
      COMMENT "sim: scenario ${n}" VERBATIM)
    list(APPEND _scenario_outputs ${_sum})
  endforeach()
  set(_sweep ${RAILPROOF_RESULTS_DIR}/analysis/scenario_gap_sweep.json)
  add_custom_command(
    OUTPUT ${_sweep}
    COMMAND line_sim --scenario ${RAILPROOF_SOURCE_DIR}/spec/scenarios/d5_follow_20kmh.json
            --lines-dir ${RAILPROOF_GEN_DIR}/lines --quiet --sweep-leader-cap 20,40,60,80 --summary ${_sweep}
    DEPENDS line_sim ${RAILPROOF_SOURCE_DIR}/spec/scenarios/d5_follow_20kmh.json ${RAILPROOF_LINE_JSON}
    COMMENT "sim: follower gap against leader speed (D5 field test)" VERBATIM)
  list(APPEND _scenario_outputs ${_sweep})
endif()

# Braking (spec/design/braking.md): the D3 speed-check design, the worst-case margin
# verification over every line and train type (Ipopt, grid/corner, OMPL falsifier; exits
# non-zero naming the location of any negative margin) and the SMT proofs (z3 and cvc5).
set(_braking_outputs)
set(_braking_dir ${RAILPROOF_RESULTS_DIR}/braking)
if(TARGET speedcheck_design)
  set(_sc_trains)
  foreach(t ${RAILPROOF_TRAIN_JSON})
    list(APPEND _sc_trains --train-json ${t})
  endforeach()
  set(_sc ${RAILPROOF_RESULTS_DIR}/analysis/speed_check_design.json)
  add_custom_command(
    OUTPUT ${_sc} ${_braking_dir}/speed_check_design.svg
    COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/analysis ${_braking_dir}
    COMMAND speedcheck_design --json ${_sc} --svg ${_braking_dir}/speed_check_design.svg
            ${_sc_trains}
    DEPENDS speedcheck_design ${RAILPROOF_TRAIN_JSON}
    COMMENT "analysis: two-counter speed-check design (D3)" VERBATIM)
  list(APPEND _braking_outputs ${_sc})
endif()
if(TARGET margins)
  set(_margins ${RAILPROOF_RESULTS_DIR}/analysis/margins.json)
  set(_margin_lines)
  foreach(l ${RAILPROOF_LINE_JSON})
    list(APPEND _margin_lines --line ${l})
  endforeach()
  set(_margin_trains)
  foreach(t ${RAILPROOF_TRAIN_JSON})
    list(APPEND _margin_trains --train ${t})
  endforeach()
  add_custom_command(
    OUTPUT ${_margins}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/analysis ${_braking_dir}
    COMMAND margins ${_margin_lines} ${_margin_trains} --json ${_margins}
            --details ${_braking_dir}/margins_locations.json --svg-dir ${_braking_dir}
    DEPENDS margins ${RAILPROOF_LINE_JSON} ${RAILPROOF_TRAIN_JSON}
    COMMENT "analysis: worst-case braking margins (every line x train type)" USES_TERMINAL VERBATIM)
  list(APPEND _braking_outputs ${_margins})
endif()
file(GLOB_RECURSE _proof_sources CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/proofs/*)
if(EXISTS ${RAILPROOF_SOURCE_DIR}/testgen/railproof_testgen/proofs.py)
  set(_proofs ${RAILPROOF_RESULTS_DIR}/proofs/braking.json)
  add_custom_command(
    OUTPUT ${_proofs}
    COMMAND ${RAILPROOF_TESTGEN} proofs --spec ${RAILPROOF_SOURCE_DIR}/spec
            --proofs ${RAILPROOF_SOURCE_DIR}/proofs --out ${RAILPROOF_RESULTS_DIR}/proofs
    DEPENDS ${_proof_sources} ${RAILPROOF_SPEC_FILES} ${RAILPROOF_TESTGEN_FILES}
    COMMENT "proofs: SMT obligations from spec/ replayed by z3 and cvc5" USES_TERMINAL VERBATIM)
  list(APPEND _braking_outputs ${_proofs})
endif()

# Odometry (spec/design/odometry.md): every wheel-rail scenario of spec/wheelrail simulated
# (Box2D) and run through the C++ odometry (IMU with two and one start points, and the
# max/min-acceleration baseline); the error bound per event, the envelope every cycle, the
# margin and clearing-time tables. Exits non-zero naming the scenario and event of any
# violated bound.
set(_odometry_outputs)
if(TARGET odometry_study)
  file(GLOB _wheelrail_scenarios CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/wheelrail/*.json)
  set(_study ${RAILPROOF_RESULTS_DIR}/analysis/odometry_study.json)
  add_custom_command(
    OUTPUT ${_study}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/analysis ${RAILPROOF_RESULTS_DIR}/odometry
    COMMAND odometry_study --scenarios ${RAILPROOF_SOURCE_DIR}/spec/wheelrail
            --out-dir ${RAILPROOF_RESULTS_DIR}/odometry --json ${_study}
            --trains-dir ${RAILPROOF_GEN_DIR}/trains --lines-dir ${RAILPROOF_GEN_DIR}/lines --quiet
    DEPENDS odometry_study ${_wheelrail_scenarios} ${RAILPROOF_TRAIN_JSON} ${RAILPROOF_LINE_JSON}
    COMMENT "analysis: odometry on the wheel-rail scenarios (error bound, envelope, baseline)"
    USES_TERMINAL VERBATIM)
  list(APPEND _odometry_outputs ${_study})
endif()

# Level crossings (spec/design/level-crossing.md): warning times of every crossing of the D4
# line under the timetable, for fixed treadles, on-board requests (with and without dwell
# awareness) and GNSS-time pre-arming; exits non-zero on any warning below the design time.
set(_crossing_outputs)
if(TARGET warning_study)
  set(_wstudy ${RAILPROOF_RESULTS_DIR}/analysis/warning_study.json)
  add_custom_command(
    OUTPUT ${_wstudy}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${RAILPROOF_RESULTS_DIR}/analysis ${RAILPROOF_RESULTS_DIR}/level_crossing
    COMMAND warning_study --line ${RAILPROOF_GEN_DIR}/lines/d4_local_line.json
            --timetable ${RAILPROOF_SOURCE_DIR}/spec/timetables/d4_local_line.yaml
            --trains-dir ${RAILPROOF_GEN_DIR}/trains --json ${_wstudy}
            --svg-dir ${RAILPROOF_RESULTS_DIR}/level_crossing --lead-sweep 6,8,10,12,14,16,18,20,24 --quiet
    DEPENDS warning_study ${RAILPROOF_SOURCE_DIR}/spec/timetables/d4_local_line.yaml
            ${RAILPROOF_TRAIN_JSON} ${RAILPROOF_LINE_JSON}
    COMMENT "analysis: level-crossing warning times (treadles, on-board request, GNSS time)"
    USES_TERMINAL VERBATIM)
  list(APPEND _crossing_outputs ${_wstudy})
endif()

add_custom_target(railproof_analysis_results ALL DEPENDS ${_residual} ${_scenario_outputs} ${_braking_outputs}
                  ${_odometry_outputs} ${_crossing_outputs})

set(_tools ${RAILPROOF_RESULTS_DIR}/tool-versions.json)
add_custom_command(
  OUTPUT ${_tools}
  COMMAND ${RAILPROOF_TESTGEN} toolversions --out ${_tools} --compiler ${CMAKE_CXX_COMPILER}
  DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/requirements.txt
  COMMENT "evidence: recording tool versions" VERBATIM)

set(_trace ${RAILPROOF_RESULTS_DIR}/trace.json)
file(GLOB_RECURSE _traced_sources CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/cpp/*.cpp ${RAILPROOF_SOURCE_DIR}/cpp/*.hpp ${RAILPROOF_SOURCE_DIR}/models/*.pml)
add_custom_command(
  OUTPUT ${_trace}
  COMMAND ${RAILPROOF_TESTGEN} trace --spec ${RAILPROOF_SOURCE_DIR}/spec --src ${RAILPROOF_SOURCE_DIR}
          --results ${RAILPROOF_RESULTS_DIR} --out ${_trace}
  DEPENDS ${_spin_outputs} ${_vector_outputs} ${_residual} ${_scenario_outputs} ${_braking_outputs}
          ${_odometry_outputs} ${_crossing_outputs} ${_traced_sources} ${_proof_sources} ${RAILPROOF_SPEC_FILES}
  COMMENT "trace: requirement <-> property/vector/code/test links" VERBATIM)

set(_manifest ${CMAKE_BINARY_DIR}/evidence/manifest.json)
file(GLOB_RECURSE _evidence_sources CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/evidence/*)
add_custom_command(
  OUTPUT ${_manifest}
  COMMAND ${RAILPROOF_TESTGEN} evidence --spec ${RAILPROOF_SOURCE_DIR}/spec --results ${RAILPROOF_RESULTS_DIR}
          --src ${RAILPROOF_SOURCE_DIR} --out ${CMAKE_BINARY_DIR}/evidence --tool-versions ${_tools}
  DEPENDS ${_trace} ${_evidence_tests} ${_residual} ${_scenario_outputs} ${_braking_outputs} ${_tools}
          ${_odometry_outputs} ${_crossing_outputs}
          ${_evidence_sources}
  COMMENT "evidence: rendering the assessor's package (Sphinx + sphinx-needs)" USES_TERMINAL VERBATIM)
add_custom_target(evidence DEPENDS ${_manifest})

# ---- pipeline checks in the test suite --------------------------------------------------
add_test(NAME testgen_pytest
  COMMAND ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} ${RAILPROOF_PYTHON} -m pytest -q -p no:cacheprovider
          ${RAILPROOF_SOURCE_DIR}/testgen/tests)
add_test(NAME traceability
  COMMAND ${RAILPROOF_TESTGEN} trace --spec ${RAILPROOF_SOURCE_DIR}/spec --src ${RAILPROOF_SOURCE_DIR}
          --results ${RAILPROOF_RESULTS_DIR} --out ${CMAKE_BINARY_DIR}/ctest-trace.json)
add_test(NAME spec_validate
  COMMAND ${RAILPROOF_TESTGEN} validate --spec ${RAILPROOF_SOURCE_DIR}/spec)
set_tests_properties(testgen_pytest traceability spec_validate PROPERTIES LABELS pipeline)

# Negative test of the margin verification (REQ-BR-009): the deliberately weakened train
# type of spec/trains/mutants must fail loudly, naming the location.
if(TARGET margins)
  set(_weak ${RAILPROOF_GEN_DIR}/trains/mutants/emu3_d1_weak.json)
  add_test(NAME margins_fails_on_weakened_train
    COMMAND margins --line ${RAILPROOF_GEN_DIR}/lines/d1_test_line.json --train ${_weak}
            --json ${CMAKE_BINARY_DIR}/ctest-margins-weak.json --falsify-budget-s 0.2 --quiet)
  set_tests_properties(margins_fails_on_weakened_train PROPERTIES LABELS "analysis;seeded_fault"
    WILL_FAIL TRUE)
  add_test(NAME margins_names_the_location_on_weakened_train
    COMMAND margins --line ${RAILPROOF_GEN_DIR}/lines/d1_test_line.json --train ${_weak}
            --json ${CMAKE_BINARY_DIR}/ctest-margins-weak2.json --falsify-budget-s 0 --quiet)
  set_tests_properties(margins_names_the_location_on_weakened_train PROPERTIES LABELS "analysis;seeded_fault"
    PASS_REGULAR_EXPRESSION "NEGATIVE MARGIN: line d1_test_line, running line (up|down), train emu3_d1_weak, class [a-z_]+, id '[^']+', stop limit at [0-9.]+ m, margin -[0-9.]+ m")
endif()
