# The wayside unit (wayside_unit.hpp, spec/design/units.md): the radio endpoints of the trains
# of its base stations, the moving-block ground, the crossing controllers and the centre
# schedulers on the ground cycle, and the handover of a train to the next unit. Its tests are
# in the units' test set (CMakeLists.txt).
railproof_runtime_module(wayside_unit CAPABILITY units SIDE wayside
  SOURCES src/wayside/wayside_unit.cpp src/wayside/wayside_cycle.cpp
  LINKS tg mb_wayside lc_wayside messages)
set(RAILPROOF_UNITS_WAYSIDE_TESTS tests/wayside/test_wayside_unit.cpp tests/wayside/test_wayside_handover.cpp
    tests/wayside/test_wayside_replay.cpp tests/wayside/test_wayside_vectors.cpp)
