# The evidence pipeline (conventions §1), driven by the capability registry: model checking
# -> vectors -> conformance -> traceability -> evidence. Every step is a build product whose
# dependencies are exactly the files it reads, so independent steps run in parallel and a
# second run with nothing changed does nothing.
#
#   ALL       : per model: SPIN verification of every property and mutant (fails on any
#               violation, printing the counterexample) and, independently, vector generation
#               with goal coverage; per capability with proofs: the SMT proofs; the studies
#               the offline modules register (railproof_study); the registry and layout checks.
#   evidence  : the test suite's results (one ctest run, JUnit), tool versions, trace.json and
#               the rendered evidence package in ${CMAKE_BINARY_DIR}/evidence (verdict and
#               reasons in evidence/evidence.json).
set(RAILPROOF_VECTOR_DIR ${RAILPROOF_RESULTS_DIR}/vectors)
set(_tg ${RAILPROOF_SOURCE_DIR}/testgen/railproof_testgen)
# what every testgen command runs (the command line and its error types); each step adds the
# modules it runs (the command line imports only the module of the command)
set(_tg_base ${_tg}/__init__.py ${_tg}/__main__.py ${_tg}/errors.py ${_tg}/files.py)
set(_tg_spin ${_tg_base} ${_tg}/spin.py)
# the vector engine and what it finds a model's capability part with (the registry)
set(_tg_engine ${_tg}/vectors.py ${_tg}/spec.py ${_tg}/registry.py ${_tg}/capabilities/__init__.py
    ${RAILPROOF_SOURCE_DIR}/spec/capabilities.yaml ${RAILPROOF_SOURCE_DIR}/spec/schemas/capabilities.schema.json)

# SPIN and vector generation are memory- and CPU-heavy: at most two at a time (each runs its
# own searches on two worker threads).
set_property(GLOBAL APPEND PROPERTY JOB_POOLS railproof_spin=2)

set(_spin_outputs)
set(_vector_outputs)
foreach(cap ${RAILPROOF_CAPABILITIES})
  # the parts the capability's models share (models/include/<cap>_*.pml)
  file(GLOB _shared CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/models/include/${cap}_*.pml)
  foreach(model ${RAILPROOF_CAP_${cap}_MODELS})
    set(_pml ${RAILPROOF_SOURCE_DIR}/models/${model}.pml)
    set(_params ${RAILPROOF_GEN_DIR}/models/${cap}_params.pml)
    set(_spin_json ${RAILPROOF_RESULTS_DIR}/spin/${model}.json)
    add_custom_command(
      OUTPUT ${_spin_json}
      COMMAND ${RAILPROOF_TESTGEN} verify --model ${_pml} --params ${RAILPROOF_GEN_DIR}/models
              --work ${CMAKE_BINARY_DIR}/spin/${model}/verify --out ${_spin_json} --jobs 2
      DEPENDS ${_pml} ${_shared} ${_params} ${_tg_spin}
      COMMENT "SPIN: exhaustive verification of models/${model}.pml (properties, mutants)"
      JOB_POOL railproof_spin VERBATIM)
    set(_vec ${RAILPROOF_VECTOR_DIR}/${model}.jsonl)
    file(GLOB _just CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/justifications/${cap}.yaml)
    add_custom_command(
      OUTPUT ${_vec} ${RAILPROOF_VECTOR_DIR}/${model}.coverage.json
      COMMAND ${RAILPROOF_TESTGEN} vectors --model ${_pml} --params ${RAILPROOF_GEN_DIR}/models
              --spec ${RAILPROOF_SOURCE_DIR}/spec --work ${CMAKE_BINARY_DIR}/spin/${model}/vectors
              --out ${RAILPROOF_VECTOR_DIR} --jobs 2
      DEPENDS ${_pml} ${_shared} ${_params} ${_tg_spin} ${_tg_engine} ${_tg}/capabilities/${cap}.py
              ${RAILPROOF_SOURCE_DIR}/spec/schemas/vectors_${cap}.schema.json
              ${RAILPROOF_SOURCE_DIR}/spec/schemas/vector_header.schema.json ${_just}
      COMMENT "testgen: trap, boundary and random-walk vectors from models/${model}.pml"
      JOB_POOL railproof_spin VERBATIM)
    list(APPEND _spin_outputs ${_spin_json})
    list(APPEND _vector_outputs ${_vec})
  endforeach()
endforeach()
add_custom_target(railproof_models ALL DEPENDS ${_spin_outputs} ${_vector_outputs})

# SMT proofs of the capabilities that have them (proofs/<cap>/), replayed by z3 and cvc5.
set(_proof_outputs)
file(GLOB_RECURSE _proof_sources CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/proofs/*)
foreach(cap ${RAILPROOF_CAPABILITIES})
  if(RAILPROOF_CAP_${cap}_PROOFS)
    file(GLOB _cap_proofs CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/proofs/${cap}/*)
    set(_proofs ${RAILPROOF_RESULTS_DIR}/proofs/${cap}.json)
    add_custom_command(
      OUTPUT ${_proofs}
      COMMAND ${RAILPROOF_TESTGEN} proofs --spec ${RAILPROOF_SOURCE_DIR}/spec
              --proofs ${RAILPROOF_SOURCE_DIR}/proofs --out ${RAILPROOF_RESULTS_DIR}/proofs
      DEPENDS ${_cap_proofs} ${RAILPROOF_PARAM_FILES} ${RAILPROOF_TRAIN_FILES} ${_tg_base} ${_tg}/spec.py
              ${_tg}/proofs.py
      COMMENT "proofs: SMT obligations of proofs/${cap} from spec/, replayed by z3 and cvc5" VERBATIM)
    list(APPEND _proof_outputs ${_proofs})
  endif()
endforeach()

# The studies the offline modules declare (railproof_study): one build step each. Their
# plots and details go to results/<cap>/ (created here; the tools also create what they need).
foreach(cap ${RAILPROOF_CAPABILITIES})
  file(MAKE_DIRECTORY ${RAILPROOF_RESULTS_DIR}/${cap})
endforeach()
get_property(_studies GLOBAL PROPERTY RAILPROOF_STUDIES)
set(_study_outputs)
foreach(s ${_studies})
  get_property(_out GLOBAL PROPERTY RAILPROOF_STUDY_${s}_OUTPUTS)
  get_property(_cmd GLOBAL PROPERTY RAILPROOF_STUDY_${s}_COMMAND)
  get_property(_dep GLOBAL PROPERTY RAILPROOF_STUDY_${s}_DEPENDS)
  get_property(_comment GLOBAL PROPERTY RAILPROOF_STUDY_${s}_COMMENT)
  set(_dirs)
  foreach(o ${_out})
    get_filename_component(d ${o} DIRECTORY)
    list(APPEND _dirs ${d})
  endforeach()
  list(REMOVE_DUPLICATES _dirs)
  add_custom_command(OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${_dirs}
    COMMAND ${_cmd}
    DEPENDS ${_dep}
    COMMENT "${_comment}" VERBATIM)
  list(GET _out 0 _result)
  list(APPEND _study_outputs ${_result})
endforeach()
add_custom_target(railproof_analysis_results ALL DEPENDS ${_proof_outputs} ${_study_outputs})

# ---- checks of the tree itself -----------------------------------------------------------
set(_layout ${RAILPROOF_RESULTS_DIR}/layout.json)
file(GLOB_RECURSE _cpp_sources CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/cpp/*.cpp ${RAILPROOF_SOURCE_DIR}/cpp/*.hpp)
add_custom_command(
  OUTPUT ${_layout}
  COMMAND ${RAILPROOF_TESTGEN} layout --repo ${RAILPROOF_SOURCE_DIR} --targets ${RAILPROOF_GEN_DIR}/targets.json
          --out ${_layout}
  DEPENDS ${RAILPROOF_GEN_DIR}/targets.json ${_cpp_sources} ${_tg_base} ${_tg}/layout.py
  COMMENT "layout: module boundaries (runtime/offline, train/ground) and include rules" VERBATIM)
add_custom_target(railproof_layout ALL DEPENDS ${_layout})

# ---- the test suite's results, for the evidence -------------------------------------------
# One ctest run of the whole suite (the same as `ctest --preset default`), as a build step:
# it reruns only when something it tests changed. Its JUnit file and the per-test GoogleTest
# XML under results/tests are what the evidence reads; the tests are never run again for it.
set(_tests_dir ${RAILPROOF_RESULTS_DIR}/tests)
set(_test_stamp ${_tests_dir}/suite.stamp)
file(GLOB_RECURSE _pytests CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/tests/*)
file(GLOB_RECURSE _testgen_py CONFIGURE_DEPENDS ${_tg}/*.py)
file(GLOB_RECURSE _test_data CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/cpp/*.json
  ${RAILPROOF_SOURCE_DIR}/cpp/runtime/tg/fuzz/corpus/*)
get_property(_test_targets GLOBAL PROPERTY RAILPROOF_TARGET_KINDS)
set(_test_exes)
foreach(entry ${_test_targets})
  string(REPLACE "=" ";" kv "${entry}")
  list(GET kv 0 t)
  get_target_property(_type ${t} TYPE)
  if(_type STREQUAL "EXECUTABLE")
    list(APPEND _test_exes ${t})
  endif()
endforeach()
add_custom_command(
  OUTPUT ${_test_stamp}
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DJUNIT=${_tests_dir}/ctest.junit.xml
          -DSTAMP=${_test_stamp} -P ${RAILPROOF_SOURCE_DIR}/cmake/RunTestSuite.cmake
  DEPENDS ${_test_exes} ${_spin_outputs} ${_vector_outputs} ${_proof_outputs} ${_study_outputs} ${_layout}
          ${_pytests} ${_testgen_py} ${_test_data} ${RAILPROOF_SPEC_FILES} ${RAILPROOF_LINE_JSON}
          ${RAILPROOF_TRAIN_JSON}
  COMMENT "tests: the whole suite (ctest) -> results/tests" USES_TERMINAL VERBATIM)
add_custom_target(test-results DEPENDS ${_test_stamp})

set(_tools ${RAILPROOF_RESULTS_DIR}/tool-versions.json)
add_custom_command(
  OUTPUT ${_tools}
  COMMAND ${RAILPROOF_TESTGEN} toolversions --out ${_tools} --compiler ${CMAKE_CXX_COMPILER}
  DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/requirements.txt ${_tg_base} ${_tg}/toolversions.py
  COMMENT "evidence: recording tool versions" VERBATIM)

set(_trace ${RAILPROOF_RESULTS_DIR}/trace.json)
file(GLOB_RECURSE _traced_sources CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/cpp/*.cpp ${RAILPROOF_SOURCE_DIR}/cpp/*.hpp ${RAILPROOF_SOURCE_DIR}/models/*.pml)
add_custom_command(
  OUTPUT ${_trace}
  COMMAND ${RAILPROOF_TESTGEN} trace --spec ${RAILPROOF_SOURCE_DIR}/spec --src ${RAILPROOF_SOURCE_DIR}
          --results ${RAILPROOF_RESULTS_DIR} --out ${_trace}
  DEPENDS ${_spin_outputs} ${_vector_outputs} ${_proof_outputs} ${_study_outputs} ${_traced_sources}
          ${_proof_sources} ${RAILPROOF_SPEC_FILES} ${RAILPROOF_SPEC_TOOL_FILES} ${_tg}/trace.py
          ${_tg}/registry.py
  COMMENT "trace: requirement <-> property/vector/code/test links" VERBATIM)
add_custom_target(railproof_trace ALL DEPENDS ${_trace})

# The evidence reads every result above (it never runs a test: the JUnit files come from the
# test-results step) and the design notes; it is rendered again when any of them changes.
set(_manifest ${CMAKE_BINARY_DIR}/evidence/manifest.json)
file(GLOB_RECURSE _evidence_sources CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/evidence/*)
file(GLOB_RECURSE _evidence_py CONFIGURE_DEPENDS ${_tg}/evidence/*.py)
file(GLOB _design_notes CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/spec/design/*.md)
set(_evidence_command ${RAILPROOF_TESTGEN} evidence --spec ${RAILPROOF_SOURCE_DIR}/spec --results ${RAILPROOF_RESULTS_DIR}
    --src ${RAILPROOF_SOURCE_DIR} --out ${CMAKE_BINARY_DIR}/evidence)
add_custom_command(
  OUTPUT ${_manifest}
  COMMAND ${_evidence_command}
  DEPENDS ${_trace} ${_test_stamp} ${_tools} ${_layout} ${RAILPROOF_RESULTS_DIR}/registry.json
          ${_spin_outputs} ${_vector_outputs} ${_proof_outputs} ${_study_outputs}
          ${RAILPROOF_SPEC_FILES} ${_design_notes} ${_evidence_sources} ${_evidence_py} ${_tg_base}
          ${_tg}/spec.py ${_tg}/toolversions.py
  COMMENT "evidence: rendering the assessor's package (Sphinx + sphinx-needs)" VERBATIM)
# After a failed test suite the package is still rendered, from the results the failed run
# left, with the verdict FAIL and its reasons (./railproof does this; it never depends on the
# suite's success stamp).
add_custom_target(evidence-after-failure
  COMMAND ${_evidence_command}
  DEPENDS ${_trace} ${_tools} ${_layout}
  COMMENT "evidence: rendering the assessor's package after a failed test suite" VERBATIM)
add_custom_target(evidence DEPENDS ${_manifest})

# ---- pipeline checks in the test suite (they read the build's results) -----------------------
add_test(NAME spec_validate COMMAND ${RAILPROOF_TESTGEN} validate --spec ${RAILPROOF_SOURCE_DIR}/spec)
add_test(NAME registry_agrees_with_tree
  COMMAND ${RAILPROOF_TESTGEN} registry --spec ${RAILPROOF_SOURCE_DIR}/spec --repo ${RAILPROOF_SOURCE_DIR} --check)
add_test(NAME layout_boundaries
  COMMAND ${RAILPROOF_TESTGEN} layout --repo ${RAILPROOF_SOURCE_DIR} --targets ${RAILPROOF_GEN_DIR}/targets.json)
add_test(NAME traceability
  COMMAND ${RAILPROOF_TESTGEN} trace --spec ${RAILPROOF_SOURCE_DIR}/spec --src ${RAILPROOF_SOURCE_DIR}
          --results ${RAILPROOF_RESULTS_DIR} --out ${CMAKE_BINARY_DIR}/ctest-trace.json)
set_tests_properties(spec_validate registry_agrees_with_tree layout_boundaries traceability PROPERTIES LABELS pipeline)
# testgen's own tests: one ctest entry per test file (they run in parallel). They use tiny
# fixtures; the tests marked `pipeline` check the real results of this build
# (RAILPROOF_RESULTS_DIR) instead of regenerating them.
file(GLOB _pytest_files CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/tests/test_*.py)
foreach(f ${_pytest_files})
  get_filename_component(n ${f} NAME_WE)
  add_test(NAME testgen.${n}
    COMMAND ${CMAKE_COMMAND} -E env ${RAILPROOF_PY_ENV} RAILPROOF_RESULTS_DIR=${RAILPROOF_RESULTS_DIR}
            RAILPROOF_GEN_DIR=${RAILPROOF_GEN_DIR}
            ${RAILPROOF_PYTHON} -m pytest -q -p no:cacheprovider ${f} --junitxml=${_tests_dir}/testgen/${n}.xml)
  set_tests_properties(testgen.${n} PROPERTIES LABELS "pipeline;testgen")
endforeach()
