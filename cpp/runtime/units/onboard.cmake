# The on-board unit (onboard_unit.hpp, spec/design/units.md): the train-side parts of the
# capabilities composed into one cycle. Its tests are in the units' test set (CMakeLists.txt).
railproof_runtime_module(onboard_unit CAPABILITY units SIDE onboard
  SOURCES src/onboard/onboard_unit.cpp src/onboard/onboard_profile.cpp
  LINKS tg mb_onboard br ra lc_onboard messages)
set(RAILPROOF_UNITS_ONBOARD_TESTS tests/onboard/test_onboard_unit.cpp tests/onboard/test_onboard_profile.cpp
    tests/onboard/test_onboard_replay.cpp tests/onboard/test_onboard_crossing_replay.cpp
    tests/onboard/test_onboard_handover.cpp tests/onboard/test_onboard_slip_replay.cpp)
