// Unit tests of the speed supervision decision br::Supervisor::Step (spec/design/
// braking.md §4, steps 1-6): the emergency latch and its release (standstill, handle and
// reset in the same cycle), the emergency pattern with its strict comparison, the 7N/6N/5N/4N
// selection with the boundaries, the release lead hold and the "pattern approaching"
// indication. Pattern speeds are abstract (mm/s) with the ordering of an approach:
// v_e 100 > v_7n 90 > v_6n 80 > v_5n 70 > v_4n 60 > v_release 50.
//
// Kills the seeded decision faults FAULT_BR_RESET_IGNORES_HANDLE, FAULT_BR_RELEASE_WHILE_MOVING,
// FAULT_BR_NO_RELEASE_LEAD, FAULT_BR_EMERGENCY_LATE, FAULT_BR_EMERGENCY_NOT_LATCHED (build this
// file against supervisor.cpp compiled with the macro).
#include <gtest/gtest.h>

#include <cstdint>

#include "railproof/testing/enum_names.hpp"
#include "railproof/br/supervisor.hpp"

namespace railproof::br {
namespace {

PatternSpeeds At(std::int64_t v_s) {
  return PatternSpeeds{.v_s = v_s, .v_e = 100, .v_7n = 90, .v_6n = 80, .v_5n = 70, .v_4n = 60, .v_release = 50};
}

constexpr DriverInputs kNoInputs{false, false, false};
constexpr DriverInputs kAllReset{true, true, true};

// Latches the emergency brake by one overspeed cycle.
Supervisor Latched() {
  Supervisor s;
  const Decision d = s.Step(At(101), kNoInputs);
  EXPECT_EQ(d.level, BrakeLevel::kEmergency);
  EXPECT_TRUE(d.emergency_latched);
  return s;
}

// @verifies REQ-BR-001
// @verifies REQ-BR-002
// @verifies REQ-BR-003
TEST(BrakingSupervisor, LevelNamesOfTheVectors) {
  railproof::testing::ExpectEnumNames<BrakeLevel>(std::array<const char*, 6>{"NONE", "4N", "5N", "6N", "7N", "EB"});
}

// Step 2-5: at or below every pattern nothing is commanded and nothing shown.
// @verifies REQ-BR-003
TEST(BrakingSupervisor, NothingBelowEveryPattern) {
  Supervisor s;
  for (std::int64_t v : {0, 1, 49, 50}) {
    const Decision d = s.Step(At(v), kNoInputs);
    EXPECT_EQ(d.level, BrakeLevel::kNone) << v;
    EXPECT_FALSE(d.pattern_approaching) << v;
    EXPECT_FALSE(d.emergency_latched) << v;
  }
  EXPECT_EQ(s.service_level(), BrakeLevel::kNone);
  EXPECT_FALSE(s.emergency_latched());
}

// Step 2: v_s > v_e commands and latches the emergency brake at once; v_s == v_e does not.
// @verifies REQ-BR-001
TEST(BrakingSupervisor, EmergencyAboveTheEmergencyPatternOnly) {
  Supervisor s;
  Decision d = s.Step(At(100), kNoInputs);
  EXPECT_EQ(d.level, BrakeLevel::k7N);
  EXPECT_FALSE(d.emergency_latched);
  d = s.Step(At(101), kNoInputs);
  EXPECT_EQ(d.level, BrakeLevel::kEmergency);
  EXPECT_TRUE(d.emergency_latched);
  EXPECT_TRUE(d.pattern_approaching);
  EXPECT_TRUE(s.emergency_latched());
}

// Step 2 takes precedence over everything else, from any state, at zero pattern (standstill
// supervision): any v_s > 0 brakes.
// @verifies REQ-BR-001
// @verifies REQ-BR-012
TEST(BrakingSupervisor, EmergencyAtZeroPatternForAnyMovement) {
  Supervisor s;
  PatternSpeeds zero;
  zero.v_s = 0;
  EXPECT_EQ(s.Step(zero, kAllReset).level, BrakeLevel::kNone);
  zero.v_s = 1;
  EXPECT_EQ(s.Step(zero, kAllReset).level, BrakeLevel::kEmergency);
}

// Step 1: once latched, the emergency brake stays commanded even when the speed is far
// below every pattern and no driver input is given.
// @verifies REQ-BR-006
TEST(BrakingSupervisor, EmergencyStaysLatchedBelowThePattern) {
  Supervisor s = Latched();
  for (int cycle = 0; cycle < 5; ++cycle) {
    const Decision d = s.Step(At(0), kNoInputs);
    EXPECT_EQ(d.level, BrakeLevel::kEmergency) << cycle;
    EXPECT_TRUE(d.emergency_latched) << cycle;
    EXPECT_TRUE(d.pattern_approaching) << cycle;
  }
  EXPECT_TRUE(s.emergency_latched());
  EXPECT_EQ(s.service_level(), BrakeLevel::kNone);
}

// Step 1: each missing condition keeps the latch (every combination of two of the three).
// @verifies REQ-BR-006
TEST(BrakingSupervisor, EachMissingConditionKeepsTheLatch) {
  const DriverInputs partial[] = {
      {true, true, false},   // no reset
      {true, false, true},   // handle not in emergency
      {false, true, true},   // moving
      {true, false, false}, {false, true, false}, {false, false, true}, {false, false, false},
  };
  for (const DriverInputs& in : partial) {
    Supervisor s = Latched();
    const Decision d = s.Step(At(0), in);
    EXPECT_EQ(d.level, BrakeLevel::kEmergency) << in.standstill << in.handle_emergency << in.reset;
    EXPECT_TRUE(d.emergency_latched);
    EXPECT_TRUE(s.emergency_latched());
  }
}

// Step 1 (REQ-BR-006 "in the same cycle"): conditions spread over cycles do not release.
// @verifies REQ-BR-006
TEST(BrakingSupervisor, ConditionsMustHoldInTheSameCycle) {
  Supervisor s = Latched();
  EXPECT_EQ(s.Step(At(0), DriverInputs{true, true, false}).level, BrakeLevel::kEmergency);
  EXPECT_EQ(s.Step(At(0), DriverInputs{false, false, true}).level, BrakeLevel::kEmergency);
  EXPECT_EQ(s.Step(At(0), DriverInputs{true, false, true}).level, BrakeLevel::kEmergency);
  EXPECT_TRUE(s.emergency_latched());
  const Decision d = s.Step(At(0), kAllReset);
  EXPECT_EQ(d.level, BrakeLevel::kNone);
  EXPECT_FALSE(d.emergency_latched);
  EXPECT_FALSE(s.emergency_latched());
}

// Step 1 then 2-6 in the same cycle: after the release the normal decision applies; an
// overspeed in the release cycle latches again at once.
// @verifies REQ-BR-006
// @verifies REQ-BR-001
TEST(BrakingSupervisor, ReleaseCycleContinuesWithTheDecision) {
  Supervisor s = Latched();
  Decision d = s.Step(At(101), kAllReset);
  EXPECT_EQ(d.level, BrakeLevel::kEmergency);
  EXPECT_TRUE(d.emergency_latched);
  s = Latched();
  d = s.Step(At(95), kAllReset);
  EXPECT_EQ(d.level, BrakeLevel::k7N);
  EXPECT_FALSE(d.emergency_latched);
  // the emergency brake is not a service level: no release-lead hold after it
  s = Latched();
  d = s.Step(At(55), kAllReset);
  EXPECT_EQ(d.level, BrakeLevel::kNone);
  EXPECT_TRUE(d.pattern_approaching);
}

// Steps 3-4: the highest level whose pattern is exceeded; equality does not exceed.
// @verifies REQ-BR-002
// @verifies REQ-BR-003
TEST(BrakingSupervisor, ServiceLevelSelection) {
  struct Case {
    std::int64_t v_s;
    BrakeLevel level;
  };
  const Case cases[] = {
      {100, BrakeLevel::k7N}, {91, BrakeLevel::k7N}, {90, BrakeLevel::k6N}, {81, BrakeLevel::k6N},
      {80, BrakeLevel::k5N},  {71, BrakeLevel::k5N}, {70, BrakeLevel::k4N}, {61, BrakeLevel::k4N},
      {60, BrakeLevel::kNone}, {51, BrakeLevel::kNone}, {50, BrakeLevel::kNone},
  };
  for (const Case& c : cases) {
    Supervisor s;  // fresh: no previous service level
    const Decision d = s.Step(At(c.v_s), kNoInputs);
    EXPECT_EQ(d.level, c.level) << c.v_s;
    EXPECT_FALSE(d.emergency_latched) << c.v_s;
    EXPECT_EQ(s.service_level(), c.level) << c.v_s;
  }
}

// Steps 3-4 in sequence (feedback): approaching the pattern the levels follow 4N, 5N, 6N,
// 7N and back down as the speed falls.
// @verifies REQ-BR-003
TEST(BrakingSupervisor, MildBrakesInSequenceAndFeedback) {
  Supervisor s;
  const std::int64_t up[] = {55, 65, 75, 85, 95};
  const BrakeLevel up_levels[] = {BrakeLevel::kNone, BrakeLevel::k4N, BrakeLevel::k5N, BrakeLevel::k6N,
                                  BrakeLevel::k7N};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(s.Step(At(up[i]), kNoInputs).level, up_levels[i]) << up[i];
  }
  EXPECT_EQ(s.Step(At(85), kNoInputs).level, BrakeLevel::k6N);
  EXPECT_EQ(s.Step(At(75), kNoInputs).level, BrakeLevel::k5N);
  EXPECT_EQ(s.Step(At(65), kNoInputs).level, BrakeLevel::k4N);
}

// Step 5: an applied service brake is held at 4N until v_s <= v_release; without a previous
// service level the same speed commands nothing.
// @verifies REQ-BR-003
TEST(BrakingSupervisor, ReleaseLeadHoldsAnAppliedBrake) {
  Supervisor s;
  EXPECT_EQ(s.Step(At(75), kNoInputs).level, BrakeLevel::k5N);
  Decision d = s.Step(At(60), kNoInputs);  // below v_4n, above v_release: hold
  EXPECT_EQ(d.level, BrakeLevel::k4N);
  EXPECT_TRUE(d.pattern_approaching);
  d = s.Step(At(51), kNoInputs);  // still held (the hold is itself a service level)
  EXPECT_EQ(d.level, BrakeLevel::k4N);
  EXPECT_EQ(s.service_level(), BrakeLevel::k4N);
  d = s.Step(At(50), kNoInputs);  // at the release lead: released
  EXPECT_EQ(d.level, BrakeLevel::kNone);
  EXPECT_FALSE(d.pattern_approaching);
  d = s.Step(At(55), kNoInputs);  // no service level applied before: no hold
  EXPECT_EQ(d.level, BrakeLevel::kNone);
  EXPECT_TRUE(d.pattern_approaching);
}

// Step 5 from 7N directly down to between v_4n and v_release.
// @verifies REQ-BR-003
TEST(BrakingSupervisor, ReleaseLeadHoldFrom7N) {
  Supervisor s;
  EXPECT_EQ(s.Step(At(99), kNoInputs).level, BrakeLevel::k7N);
  EXPECT_EQ(s.Step(At(52), kNoInputs).level, BrakeLevel::k4N);
  EXPECT_EQ(s.Step(At(10), kNoInputs).level, BrakeLevel::kNone);
}

// Step 6: "pattern approaching" at v_s > v_release or while any brake is commanded.
// @verifies REQ-BR-003
TEST(BrakingSupervisor, PatternApproachingIndication) {
  Supervisor s;
  EXPECT_FALSE(s.Step(At(50), kNoInputs).pattern_approaching);
  EXPECT_TRUE(s.Step(At(51), kNoInputs).pattern_approaching);
  // inconsistent patterns (the decision does not rely on the ordering): a brake is shown
  // even when v_s <= v_release
  PatternSpeeds p = At(0);
  p.v_s = 40;
  p.v_7n = 30;
  p.v_release = 60;
  Supervisor t;
  const Decision d = t.Step(p, kNoInputs);
  EXPECT_EQ(d.level, BrakeLevel::k7N);
  EXPECT_TRUE(d.pattern_approaching);
}

}  // namespace
}  // namespace railproof::br
