# The wayside unit (spec/design/units.md, WAYSIDE_NOTES.md): the radio endpoints of the trains
# of its base stations, the moving-block ground, the crossing controllers and the centre
# schedulers on the ground cycle, and the handover of a train to the next unit.
railproof_runtime_module(wayside_unit SIDE wayside
  SOURCES src/wayside/wayside_unit.cpp src/wayside/wayside_cycle.cpp
  LINKS tg mb_wayside lc_wayside messages)
# One test executable: the unit's behaviour, the handover between two units and the replay of
# the mb, tg (ground role) and lc (on-board variant) vectors through the unit's interface.
railproof_test_set(wayside_unit RUNTIME
  SOURCES tests/wayside/test_wayside_unit.cpp tests/wayside/test_wayside_handover.cpp
          tests/wayside/test_wayside_replay.cpp
  LINKS wayside_unit LABELS wayside_unit)
# the replay reads the vectors of the pipeline with the capabilities' own readers: the header
# ones by include, the tg reader's object as the tg runner compiled it (not compiled twice)
target_include_directories(railproof_wayside_unit_test_objects PRIVATE ${RAILPROOF_SOURCE_DIR}/cpp/runtime)
target_compile_definitions(railproof_wayside_unit_test_objects PRIVATE
  RAILPROOF_WAYSIDE_VECTORS="${RAILPROOF_CONFORMANCE_VECTORS}")
target_sources(railproof_wayside_unit_tests PRIVATE
  $<FILTER:$<TARGET_OBJECTS:railproof_conformance_tg_objects>,INCLUDE,vector_reader>)
