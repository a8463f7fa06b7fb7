# The on-board unit (onboard_unit.hpp, spec/design/units.md): the train-side parts of the
# capabilities composed into one cycle. Its tests (one executable) check it as a unit and
# replay the capabilities' vectors through its external interface (sensor samples and
# telegram bytes in, bytes and brake demands out); the replay reads the vector files with the
# conformance runners' readers and key lists (vector_keys.hpp, the tg reader).
railproof_runtime_module(onboard_unit SIDE onboard
  SOURCES src/onboard/onboard_unit.cpp src/onboard/onboard_profile.cpp
  LINKS tg mb_onboard br ra lc_onboard messages)
railproof_test_set(onboard_unit RUNTIME
  SOURCES tests/onboard/test_onboard_unit.cpp tests/onboard/test_onboard_profile.cpp
          tests/onboard/test_onboard_replay.cpp ${CMAKE_CURRENT_SOURCE_DIR}/../tg/conformance/vector_reader.cpp
  LINKS onboard_unit)
target_include_directories(railproof_onboard_unit_test_objects PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/..)
target_compile_definitions(railproof_onboard_unit_test_objects PRIVATE
  RAILPROOF_ONBOARD_VECTORS="${RAILPROOF_CONFORMANCE_VECTORS}")
