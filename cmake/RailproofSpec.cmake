# spec/ is the single source of truth: it is validated (schemas, duplicates, dangling
# references: testgen validate) and turned into the C++ constants header and the Promela
# #define header before anything else is built. A bad spec entry fails the build with a
# message naming the file and the entry.
set(RAILPROOF_GEN_INCLUDE ${RAILPROOF_GEN_DIR}/include)
file(MAKE_DIRECTORY ${RAILPROOF_GEN_INCLUDE}/railproof/generated ${RAILPROOF_GEN_DIR}/models)
file(GLOB RAILPROOF_SPEC_FILES CONFIGURE_DEPENDS
  ${RAILPROOF_SOURCE_DIR}/spec/*/*.yaml ${RAILPROOF_SOURCE_DIR}/spec/schemas/*.json)
file(GLOB RAILPROOF_TESTGEN_FILES CONFIGURE_DEPENDS ${RAILPROOF_SOURCE_DIR}/testgen/railproof_testgen/*.py)
set(RAILPROOF_PARAM_HEADER ${RAILPROOF_GEN_INCLUDE}/railproof/generated/telegram_params.hpp)
set(RAILPROOF_PARAM_PML ${RAILPROOF_GEN_DIR}/models/telegram_params.pml)
add_custom_command(
  OUTPUT ${RAILPROOF_PARAM_HEADER} ${RAILPROOF_PARAM_PML}
  COMMAND ${RAILPROOF_TESTGEN} gen-params --spec ${RAILPROOF_SOURCE_DIR}/spec --out ${RAILPROOF_GEN_DIR}
  DEPENDS ${RAILPROOF_SPEC_FILES} ${RAILPROOF_TESTGEN_FILES}
  COMMENT "spec: validating spec/ and generating parameter headers"
  VERBATIM)
add_custom_target(railproof_gen_params DEPENDS ${RAILPROOF_PARAM_HEADER} ${RAILPROOF_PARAM_PML})
