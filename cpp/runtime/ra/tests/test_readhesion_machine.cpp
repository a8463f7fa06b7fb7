// Unit tests of the re-adhesion state machine ra::ReadhesionMachine (spec/design/
// odometry.md §5, steps 1-6): configuration validation, input validation, detection after
// confirm_cycles deviations, the start points and their discard at detection, ageing and
// the timeout boundary (active at t_max, discarded at t_max + 1), the re-adhesion judgement
// (both conditions for confirm_cycles consecutive cycles), adoption of the lowest index,
// the episode limits (margin and t_max never relaxed during an episode), sensor failures in
// every mode, the stopped state held until a balise, the balise reset in TG odometry.
// Times in cycles with the reference spacing (25 cycles = 2.5 s) and a primary start point
// 25 cycles old (the 2.5 s look-back); sections: normal 200 cycles / 1000 mm, steep
// 200 cycles / 1500 mm, tight 40 cycles / 500 mm.
//
// Kills the seeded faults FAULT_RA_TIMEOUT_OFF_BY_ONE, FAULT_RA_CONFIRM_TWO,
// FAULT_RA_SPEED_IGNORED, FAULT_RA_EPISODE_RELAXES, FAULT_RA_LAST_CANDIDATE_WINS,
// FAULT_RA_TG_FAILURE_IGNORED (ctest unit_fault_<F>: these tests against the schemata variant with the fault selected).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <utility>

#include "railproof/testing/enum_names.hpp"
#include "railproof/testing/alloc_counter.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/readhesion_machine.hpp"

namespace railproof::ra {
namespace {

namespace prm = railproof::params::ra;

constexpr SectionLimits kNormal{200, 1000};
constexpr SectionLimits kSteep{200, 1500};
constexpr SectionLimits kTight{40, 500};
constexpr std::int32_t kStartAge = 25;
constexpr std::int32_t kSpacing = 25;

constexpr std::int32_t kWarmup = static_cast<std::int32_t>((prm::moving_average_ms + prm::tg_window_ms) / prm::cycle_ms);

MachineConfig Config(std::uint8_t points = 2, std::uint8_t confirm = 3) {
  MachineConfig c;
  c.confirm_cycles = confirm;
  c.start_points = points;
  c.spacing_cycles = kSpacing;
  c.warmup_cycles = kWarmup;
  return c;
}

// The predicates of one cycle with healthy sensors and no balise.
Predicates In(bool deviation, SectionLimits s = kNormal, bool sa0 = false, bool sa1 = false) {
  Predicates p;
  p.deviation = deviation;
  p.speed_agrees = {sa0, sa1};
  p.section = s;
  p.start_age_cycles = kStartAge;
  return p;
}

// One cycle that must be accepted.
const MachineState& Cycle(ReadhesionMachine& m, const Predicates& p) {
  EXPECT_EQ(m.Step(p), MachineError::kNone);
  return m.state();
}

// A machine past its start-up: the warm-up at standstill (healthy, no TG pulse), after which
// it is in TG odometry with the history trusted (REQ-RA-015).
ReadhesionMachine Running(const MachineConfig& c) {
  ReadhesionMachine m(c);
  for (int k = 0; k < c.warmup_cycles; ++k) Cycle(m, In(false));
  EXPECT_EQ(m.state().mode, Mode::kTg);
  EXPECT_TRUE(m.state().trusted);
  return m;
}

// Drives a fresh machine through a detection (confirm_cycles deviations).
const MachineState& Detect(ReadhesionMachine& m, SectionLimits s = kNormal, std::int32_t age = kStartAge) {
  Predicates p = In(true, s);
  p.start_age_cycles = age;
  for (int k = 1; k < m.config().confirm_cycles; ++k) {
    Cycle(m, p);
  }
  return Cycle(m, p);
}

// A compensating cycle with no deviation; sa0/sa1 the speed agreement of each candidate.
const MachineState& Judge(ReadhesionMachine& m, bool sa0, bool sa1, SectionLimits s = kNormal) {
  return Cycle(m, In(false, s, sa0, sa1));
}

// Detects, then judges one compensating cycle per entry (the speed agreement of each
// candidate); the state after the last.
const MachineState& DetectThenJudge(ReadhesionMachine& m, std::initializer_list<std::array<bool, 2>> agreements) {
  Detect(m);
  for (const std::array<bool, 2>& a : agreements) {
    Judge(m, a[0], a[1]);
  }
  return m.state();
}

// Step 6: the stopped state with its reason, the stop demand and the position invalid.
void ExpectStopped(const MachineState& s, StopReason reason) {
  EXPECT_EQ(s.mode, Mode::kStopped);
  EXPECT_EQ(s.stop_reason, reason);
  EXPECT_TRUE(s.stop_demand);
  EXPECT_FALSE(s.position_valid);
}

// Step 5: candidate `adopted` taken, back in TG odometry, every candidate discarded.
void ExpectAdopted(const MachineState& s, std::int8_t adopted) {
  EXPECT_EQ(s.adopted, adopted);
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_FALSE(s.candidates[0].active);
  EXPECT_FALSE(s.candidates[1].active);
}

// @verifies REQ-RA-003
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, ConfigurationValidation) {
  struct Case {
    std::uint8_t points;
    std::uint8_t confirm;
    std::int32_t spacing;
    MachineError expected;
  };
  for (const Case& k : {Case{2, 3, kSpacing, MachineError::kNone}, Case{1, 3, kSpacing, MachineError::kNone},
                        Case{2, 0, kSpacing, MachineError::kConfirmCyclesInvalid},
                        Case{2, 101, kSpacing, MachineError::kConfirmCyclesInvalid},
                        Case{2, 100, kSpacing, MachineError::kNone},
                        Case{0, 3, kSpacing, MachineError::kStartPointsInvalid},
                        Case{3, 3, kSpacing, MachineError::kStartPointsInvalid},
                        Case{2, 3, 0, MachineError::kSpacingInvalid}, Case{2, 3, 10001, MachineError::kSpacingInvalid},
                        Case{2, 3, 10000, MachineError::kNone}}) {
    MachineConfig c = Config(k.points, k.confirm);
    c.spacing_cycles = k.spacing;
    EXPECT_EQ(ReadhesionMachine::Validate(c), k.expected)
        << "points " << int{k.points} << ", confirm " << int{k.confirm} << ", spacing " << k.spacing;
  }
  for (const auto& [warmup, expected] : {std::pair{0, MachineError::kWarmupInvalid}, std::pair{1, MachineError::kNone},
                                         std::pair{10000, MachineError::kNone},
                                         std::pair{10001, MachineError::kWarmupInvalid}}) {
    MachineConfig c = Config();
    c.warmup_cycles = warmup;
    EXPECT_EQ(ReadhesionMachine::Validate(c), expected) << "warmup " << warmup;
  }
  // the reference configuration (spec/parameters/ra.yaml)
  MachineConfig ref;
  ref.confirm_cycles = static_cast<std::uint8_t>(prm::confirm_cycles);
  ref.start_points = static_cast<std::uint8_t>(prm::parallel_start_points);
  ref.spacing_cycles = static_cast<std::int32_t>(prm::parallel_spacing_ms / prm::cycle_ms);
  ref.warmup_cycles = kWarmup;
  EXPECT_EQ(ReadhesionMachine::Validate(ref), MachineError::kNone);
  EXPECT_EQ(ref.spacing_cycles, kSpacing);
  for (MachineError e : {MachineError::kNone, MachineError::kConfirmCyclesInvalid, MachineError::kStartPointsInvalid,
                         MachineError::kSpacingInvalid, MachineError::kWarmupInvalid, MachineError::kSectionInvalid,
                         MachineError::kStartAgeInvalid}) {
    EXPECT_STRNE(ToString(e), "unknown");
  }
  EXPECT_STREQ(ToString(static_cast<MachineError>(99)), "unknown");
}

// The names the conformance vectors use (models/ra.pml, ra_vectors.py).
// @verifies REQ-RA-007
// @verifies REQ-RA-013
TEST(OdometryReadhesionMachine, NamesOfTheVectors) {
  railproof::testing::ExpectEnumNames<Mode>(std::array<const char*, 3>{"TG", "COMPENSATING", "STOPPED"});
  railproof::testing::ExpectEnumNames<StopReason>(std::array<const char*, 6>{
      "NONE", "MAX_COMPENSATION_TIME", "IMU_FAILURE", "TG_FAILURE", "START_UP", "START_IN_MOTION"});
}

// Steps 1 and 4: after the warm-up the machine is in TG odometry with a valid position; each
// cycle takes the section's limits; deviations below confirm_cycles only count.
// @verifies REQ-RA-003
// @verifies REQ-RA-009
TEST(OdometryReadhesionMachine, AfterTheWarmUpInTgOdometryWithTheSectionLimits) {
  ReadhesionMachine m = Running(Config());
  EXPECT_EQ(m.state().mode, Mode::kTg);
  EXPECT_TRUE(m.state().position_valid);
  EXPECT_FALSE(m.state().stop_demand);
  EXPECT_EQ(m.state().adopted, kNoCandidate);
  const MachineState& s = Cycle(m, In(false, kSteep));
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_EQ(s.max_compensation_cycles, 200);
  EXPECT_EQ(s.margin_mm, 1500);
  EXPECT_EQ(s.deviation_count, 0);
  EXPECT_FALSE(s.detected);
}

// Invalid section limits or a negative start-point age on a detection cycle are rejected
// and change nothing; a negative age outside a detection cycle is not read.
// @verifies REQ-RA-009
// @verifies REQ-RA-004
TEST(OdometryReadhesionMachine, InvalidInputsRejectedWithoutChange) {
  ReadhesionMachine m = Running(Config());
  Cycle(m, In(true));
  Predicates bad = In(true, SectionLimits{0, 1000});
  EXPECT_EQ(m.Step(bad), MachineError::kSectionInvalid);
  bad = In(true, SectionLimits{200, -1});
  EXPECT_EQ(m.Step(bad), MachineError::kSectionInvalid);
  EXPECT_EQ(m.state().deviation_count, 1);
  Predicates young = In(true);
  young.start_age_cycles = -1;
  Cycle(m, young);  // second deviation: not a detection cycle, the age is not read
  EXPECT_EQ(m.state().deviation_count, 2);
  EXPECT_EQ(m.Step(young), MachineError::kStartAgeInvalid);  // third: detection
  EXPECT_EQ(m.state().mode, Mode::kTg);
  EXPECT_EQ(m.state().deviation_count, 2);
  const MachineState& s = Cycle(m, In(true));
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_TRUE(s.detected);
}

// Step 4: detection exactly at confirm_cycles consecutive deviations; an interruption
// restarts the count; the start points are start_age and start_age + spacing old.
// @verifies REQ-RA-003
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, DetectionAfterConfirmCyclesWithTwoStartPoints) {
  ReadhesionMachine m = Running(Config());
  Cycle(m, In(true));
  Cycle(m, In(true));
  EXPECT_EQ(m.state().deviation_count, 2);
  Cycle(m, In(false));  // interrupted: no detection, the count restarts
  EXPECT_EQ(m.state().mode, Mode::kTg);
  EXPECT_EQ(m.state().deviation_count, 0);
  Cycle(m, In(true));
  Cycle(m, In(true));
  EXPECT_EQ(m.state().mode, Mode::kTg);
  const MachineState& s = Cycle(m, In(true));
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_TRUE(s.detected);
  EXPECT_EQ(s.deviation_count, 0);
  EXPECT_TRUE(s.candidates[0].active);
  EXPECT_EQ(s.candidates[0].age_cycles, kStartAge);
  EXPECT_EQ(s.candidates[0].confirm, 0);
  EXPECT_TRUE(s.candidates[1].active);
  EXPECT_EQ(s.candidates[1].age_cycles, kStartAge + kSpacing);
  EXPECT_FALSE(s.stop_demand);
  EXPECT_TRUE(s.position_valid);
  Cycle(m, In(true));  // re-adhesion is judged from the next cycle; the event is one cycle only
  EXPECT_FALSE(m.state().detected);
  EXPECT_EQ(m.state().candidates[0].age_cycles, kStartAge + 1);
}

// @verifies REQ-RA-003
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, OneStartPointStartsOneCandidate) {
  ReadhesionMachine m = Running(Config(1));
  const MachineState& s = Detect(m);
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_TRUE(s.candidates[0].active);
  EXPECT_FALSE(s.candidates[1].active);
  EXPECT_EQ(s.candidates[1].age_cycles, 0);
}

// A configured confirmation of one cycle: detection on the first deviation, adoption on
// the first cycle with both conditions.
// @verifies REQ-RA-003
// @verifies REQ-RA-006
TEST(OdometryReadhesionMachine, ConfirmationOfOneCycle) {
  ReadhesionMachine m = Running(Config(2, 1));
  EXPECT_EQ(Cycle(m, In(true)).mode, Mode::kCompensating);
  const MachineState& s = Judge(m, true, false);
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_EQ(s.adopted, 0);
}

// Step 4: a start point older than t_max is discarded at once; none left: the stop
// demand in the detection cycle (step 6).
// @verifies REQ-RA-007
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, StartPointsOlderThanTmaxDiscardedAtDetection) {
  ReadhesionMachine m = Running(Config());
  const MachineState& s = Detect(m, kTight);  // 25 <= 40 < 50
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_TRUE(s.candidates[0].active);
  EXPECT_FALSE(s.candidates[1].active);
  EXPECT_EQ(s.candidates[1].age_cycles, 0);

  ReadhesionMachine edge = Running(Config());
  EXPECT_TRUE(Detect(edge, kTight, 40).candidates[0].active);  // exactly t_max: kept

  ReadhesionMachine old = Running(Config());
  const MachineState& t = Detect(old, kTight, 41);
  EXPECT_TRUE(t.detected);
  ExpectStopped(t, StopReason::kMaxCompensationTime);
  EXPECT_FALSE(t.candidates[0].active);
}

// Steps 5 and 6: a candidate at exactly t_max is still compensating, at t_max + 1 it is
// discarded; when it was the last, the stop demand and the invalid position in that cycle.
// @verifies REQ-RA-007
TEST(OdometryReadhesionMachine, TimeoutAtTmaxPlusOne) {
  ReadhesionMachine m = Running(Config());
  Detect(m, kTight);
  for (std::int32_t age = kStartAge + 1; age <= kTight.max_compensation_cycles; ++age) {
    const MachineState& s = Cycle(m, In(true, kTight));
    ASSERT_EQ(s.mode, Mode::kCompensating) << age;
    EXPECT_EQ(s.candidates[0].age_cycles, age);
    EXPECT_FALSE(s.stop_demand);
  }
  EXPECT_EQ(m.state().candidates[0].age_cycles, kTight.max_compensation_cycles);
  const MachineState& s = Cycle(m, In(true, kTight));
  ExpectStopped(s, StopReason::kMaxCompensationTime);
  EXPECT_FALSE(s.candidates[0].active);
}

// Step 5: the older start point times out first, the primary continues.
// @verifies REQ-RA-007
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, SecondStartPointTimesOutPrimaryContinues) {
  const SectionLimits s60{60, 1000};
  ReadhesionMachine m = Running(Config());
  Detect(m, s60);
  for (int k = 0; k < 10; ++k) {
    Cycle(m, In(true, s60));
  }
  EXPECT_TRUE(m.state().candidates[1].active);
  EXPECT_EQ(m.state().candidates[1].age_cycles, 60);
  const MachineState& s = Cycle(m, In(true, s60));
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_FALSE(s.candidates[1].active);
  EXPECT_TRUE(s.candidates[0].active);
  EXPECT_EQ(s.candidates[0].age_cycles, 36);
}

// Step 5: adoption after exactly confirm_cycles cycles with both conditions, not before;
// the adoption discards every candidate and returns to TG odometry.
// @verifies REQ-RA-006
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, ReadhesionAfterConfirmCycles) {
  ReadhesionMachine m = Running(Config());
  Detect(m);
  EXPECT_EQ(Judge(m, true, false).candidates[0].confirm, 1);
  const MachineState& two = Judge(m, true, false);
  EXPECT_EQ(two.mode, Mode::kCompensating);
  EXPECT_EQ(two.candidates[0].confirm, 2);
  EXPECT_EQ(two.candidates[1].confirm, 0);
  EXPECT_EQ(two.adopted, kNoCandidate);
  const MachineState& s = Judge(m, true, false);
  ExpectAdopted(s, 0);
  EXPECT_EQ(s.deviation_count, 0);
  EXPECT_FALSE(s.stop_demand);
  EXPECT_TRUE(s.position_valid);
  EXPECT_EQ(Cycle(m, In(false)).adopted, kNoCandidate);  // the event is one cycle only
}

// The speed condition alone failing restarts the confirmation.
// @verifies REQ-RA-006
TEST(OdometryReadhesionMachine, SpeedDisagreementRestartsTheConfirmation) {
  ReadhesionMachine m = Running(Config(1));
  Detect(m);
  Judge(m, true, false);
  Judge(m, true, false);
  const MachineState& s = Judge(m, false, false);  // no deviation, speeds disagree
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_EQ(s.candidates[0].confirm, 0);
  Judge(m, true, false);
  Judge(m, true, false);
  EXPECT_EQ(m.state().mode, Mode::kCompensating);
  EXPECT_EQ(Judge(m, true, false).adopted, 0);
}

// A deviation restarts the confirmation of every candidate, even with the speeds agreeing.
// @verifies REQ-RA-006
TEST(OdometryReadhesionMachine, DeviationRestartsTheConfirmation) {
  ReadhesionMachine m = Running(Config());
  DetectThenJudge(m, {{true, true}, {true, true}});
  const MachineState& s = Cycle(m, In(true, kNormal, true, true));
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_EQ(s.candidates[0].confirm, 0);
  EXPECT_EQ(s.candidates[1].confirm, 0);
}

// Both complete the confirmation in the same cycle: the primary (lowest index) wins.
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, BothConfirmInOneCyclePrimaryAdopted) {
  ReadhesionMachine m = Running(Config());
  ExpectAdopted(DetectThenJudge(m, {{true, true}, {true, true}, {true, true}}), 0);
}

// The second start point completes first (the primary one cycle short) and is adopted.
// @verifies REQ-RA-010
TEST(OdometryReadhesionMachine, SecondStartPointAdoptedWhenFirst) {
  ReadhesionMachine m = Running(Config());
  ExpectAdopted(DetectThenJudge(m, {{false, true}, {true, true}, {true, true}}), 1);
}

// Step 1: during an episode the margin in force only grows and t_max only shrinks; in TG
// odometry (and from the first cycle after the episode) the limits follow the section.
// @verifies REQ-RA-009
TEST(OdometryReadhesionMachine, EpisodeNeverRelaxesItsLimits) {
  ReadhesionMachine m = Running(Config());
  Cycle(m, In(false, kSteep));
  EXPECT_EQ(Cycle(m, In(false, kNormal)).margin_mm, 1000);  // TG odometry: the current section
  Detect(m, kNormal);
  EXPECT_EQ(m.state().margin_mm, 1000);
  EXPECT_EQ(Cycle(m, In(true, kSteep)).margin_mm, 1500);
  const MachineState& back = Cycle(m, In(true, kNormal));
  EXPECT_EQ(back.margin_mm, 1500);  // kept after returning to a normal section
  EXPECT_EQ(back.max_compensation_cycles, 200);
  const MachineState& tight = Cycle(m, In(true, kTight));  // ages 28 and 53: the second times out
  EXPECT_EQ(tight.max_compensation_cycles, 40);
  EXPECT_EQ(tight.margin_mm, 1500);
  EXPECT_TRUE(tight.candidates[0].active);
  EXPECT_FALSE(tight.candidates[1].active);
  const MachineState& s = Cycle(m, In(true, kNormal));
  EXPECT_EQ(s.max_compensation_cycles, 40);  // kept after returning to a normal section
  EXPECT_EQ(s.margin_mm, 1500);
  Judge(m, true, false);
  Judge(m, true, false);
  const MachineState& adopted = Judge(m, true, false);
  EXPECT_EQ(adopted.adopted, 0);
  EXPECT_EQ(adopted.max_compensation_cycles, 40);  // the adoption cycle is still the episode's
  EXPECT_EQ(adopted.margin_mm, 1500);
  const MachineState& after = Cycle(m, In(false, kNormal));
  EXPECT_EQ(after.max_compensation_cycles, 200);
  EXPECT_EQ(after.margin_mm, 1000);
}

// A tight section entered during the episode times out a compensation older than its t_max.
// @verifies REQ-RA-009
// @verifies REQ-RA-007
TEST(OdometryReadhesionMachine, TightSectionTimesOutTheEpisode) {
  ReadhesionMachine m = Running(Config());
  Detect(m);
  for (int k = 0; k < 15; ++k) {
    Cycle(m, In(true));
  }
  EXPECT_EQ(m.state().candidates[0].age_cycles, 40);
  EXPECT_EQ(m.state().mode, Mode::kCompensating);
  ExpectStopped(Cycle(m, In(true, kTight)), StopReason::kMaxCompensationTime);  // 41 > 40
}

// Step 2 in each mode: the safe reaction in the same cycle, IMU checked first.
// @verifies REQ-RA-013
TEST(OdometryReadhesionMachine, SensorFailureInEveryMode) {
  {  // TG odometry, IMU
    ReadhesionMachine m = Running(Config());
    Cycle(m, In(true));
    Predicates p = In(true);
    p.imu_ok = false;
    const MachineState& s = Cycle(m, p);
    ExpectStopped(s, StopReason::kImuFailure);
    EXPECT_EQ(s.deviation_count, 0);
  }
  {  // TG odometry, TG
    ReadhesionMachine m = Running(Config());
    Predicates p = In(false);
    p.tg_ok = false;
    ExpectStopped(Cycle(m, p), StopReason::kTgFailure);
  }
  {  // compensating, TG: every candidate discarded
    ReadhesionMachine m = Running(Config());
    Detect(m);
    Predicates p = In(false, kNormal, true, true);
    p.tg_ok = false;
    const MachineState& s = Cycle(m, p);
    ExpectStopped(s, StopReason::kTgFailure);
    EXPECT_FALSE(s.candidates[0].active);
    EXPECT_FALSE(s.candidates[1].active);
    EXPECT_EQ(s.adopted, kNoCandidate);
  }
  {  // compensating, IMU
    ReadhesionMachine m = Running(Config());
    Detect(m);
    Predicates p = In(false);
    p.imu_ok = false;
    const MachineState& s = Cycle(m, p);
    EXPECT_EQ(s.stop_reason, StopReason::kImuFailure);
    EXPECT_FALSE(s.candidates[0].active);
  }
  {  // stopped after a timeout: the reason becomes the failure; both failing: IMU
    ReadhesionMachine m = Running(Config());
    Detect(m, kTight, 41);
    EXPECT_EQ(m.state().stop_reason, StopReason::kMaxCompensationTime);
    Predicates p = In(false);
    p.tg_ok = false;
    EXPECT_EQ(Cycle(m, p).stop_reason, StopReason::kTgFailure);
    p.imu_ok = false;
    const MachineState& s = Cycle(m, p);
    EXPECT_EQ(s.stop_reason, StopReason::kImuFailure);
    EXPECT_TRUE(s.stop_demand);
  }
}

// Step 3: the stopped state is held (with its reason) until a balise is read with both
// sensors healthy; then TG odometry, valid position, accumulated error reset.
// @verifies REQ-RA-007
// @verifies REQ-RA-012
// @verifies REQ-RA-013
TEST(OdometryReadhesionMachine, StoppedHeldUntilABalise) {
  ReadhesionMachine m = Running(Config());
  Detect(m, kTight, 41);
  for (int k = 0; k < 3; ++k) {
    const MachineState& s = Cycle(m, In(true));
    ExpectStopped(s, StopReason::kMaxCompensationTime);
    EXPECT_FALSE(s.balise_reset);
  }
  Predicates p = In(false);
  p.balise = true;
  p.tg_ok = false;
  const MachineState& failing = Cycle(m, p);  // a balise with a sensor failing: still stopped
  EXPECT_EQ(failing.mode, Mode::kStopped);
  EXPECT_FALSE(failing.balise_reset);
  p.tg_ok = true;
  p.deviation = true;
  // a balise before the warm-up at standstill after the stop: still stopped (REQ-RA-015)
  ExpectStopped(Cycle(m, p), StopReason::kTgFailure);
  EXPECT_FALSE(m.state().trusted);
  EXPECT_FALSE(m.state().balise_reset);
  for (int k = 0; k < kWarmup; ++k) ExpectStopped(Cycle(m, In(false)), StopReason::kTgFailure);
  EXPECT_TRUE(m.state().trusted);
  const MachineState& s = Cycle(m, p);
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_EQ(s.stop_reason, StopReason::kNone);
  EXPECT_FALSE(s.stop_demand);
  EXPECT_TRUE(s.position_valid);
  EXPECT_TRUE(s.balise_reset);
  EXPECT_EQ(s.deviation_count, 0);  // the recovery cycle's deviation does not count
}

// Step 2a (REQ-RA-015): a fresh machine is stopped at start-up, the stop demand and the
// position invalid, until warmup_cycles healthy cycles without a TG pulse; the start-up
// then ends without a balise, in the cycle the warm-up completes.
// @verifies REQ-RA-015
TEST(OdometryReadhesionMachine, StartUpEndsWithTheWarmUpAtStandstill) {
  ReadhesionMachine m(Config());
  ExpectStopped(m.state(), StopReason::kStartUp);
  EXPECT_FALSE(m.state().trusted);
  for (int k = 1; k < kWarmup; ++k) {
    ExpectStopped(Cycle(m, In(false)), StopReason::kStartUp);
    EXPECT_EQ(m.state().rest_cycles, k);
  }
  const MachineState& s = Cycle(m, In(false));
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_EQ(s.stop_reason, StopReason::kNone);
  EXPECT_TRUE(s.position_valid);
  EXPECT_FALSE(s.stop_demand);
  EXPECT_TRUE(s.trusted);
  EXPECT_FALSE(s.balise_reset);
}

// A TG pulse before the warm-up is complete: a start in motion. The warm-up restarts; once
// trusted the stop is held until a balise (boundary: the pulse in the last cycle before the
// warm-up would complete).
// @verifies REQ-RA-015
TEST(OdometryReadhesionMachine, StartInMotionNeedsTheWarmUpAndABalise) {
  ReadhesionMachine m(Config());
  for (int k = 1; k < kWarmup; ++k) Cycle(m, In(false));
  EXPECT_EQ(m.state().rest_cycles, kWarmup - 1);
  Predicates moving = In(false);
  moving.tg_moving = true;
  ExpectStopped(Cycle(m, moving), StopReason::kStartInMotion);
  EXPECT_EQ(m.state().rest_cycles, 0);
  Predicates bal = In(false);
  bal.balise = true;
  ExpectStopped(Cycle(m, bal), StopReason::kStartInMotion);  // not trusted yet
  EXPECT_FALSE(m.state().balise_reset);
  for (int k = 1; k < kWarmup; ++k) ExpectStopped(Cycle(m, In(false)), StopReason::kStartInMotion);
  EXPECT_TRUE(m.state().trusted);
  ExpectStopped(Cycle(m, moving), StopReason::kStartInMotion);  // trusted: moving to a balise
  const MachineState& s = Cycle(m, bal);
  EXPECT_EQ(s.mode, Mode::kTg);
  EXPECT_TRUE(s.position_valid);
  EXPECT_TRUE(s.balise_reset);
}

// While a stop waits for its balise with the history trusted, confirm_cycles deviations in a
// row withdraw the trust (a TG wheel locked through the "standstill" that rolls again); one
// fewer does not (boundary). A new warm-up at standstill is needed before the balise.
// @verifies REQ-RA-015
TEST(OdometryReadhesionMachine, DeviationRunWhileWaitingWithdrawsTheTrust) {
  ReadhesionMachine m = Running(Config());
  Detect(m, kTight, 41);
  for (int k = 0; k < kWarmup; ++k) Cycle(m, In(false));
  ASSERT_TRUE(m.state().trusted);
  for (int k = 1; k < m.config().confirm_cycles; ++k) Cycle(m, In(true));
  EXPECT_TRUE(Cycle(m, In(false)).trusted);  // confirm_cycles - 1, then none: kept
  for (int k = 1; k < m.config().confirm_cycles; ++k) {
    EXPECT_TRUE(Cycle(m, In(true)).trusted);
  }
  const MachineState& s = Cycle(m, In(true));
  ExpectStopped(s, StopReason::kMaxCompensationTime);
  EXPECT_FALSE(s.trusted);
  EXPECT_EQ(s.deviation_count, 0);
  Predicates bal = In(false);
  bal.balise = true;
  ExpectStopped(Cycle(m, bal), StopReason::kMaxCompensationTime);  // trust withdrawn: held
  for (int k = 0; k < kWarmup; ++k) Cycle(m, In(false));
  EXPECT_EQ(Cycle(m, bal).mode, Mode::kTg);
}

// Every stop withdraws the trust: after a timeout a balise counts only after a new warm-up
// at standstill; a sensor failure during the start-up makes it a failure stop (a balise).
// @verifies REQ-RA-015
// @verifies REQ-RA-007
TEST(OdometryReadhesionMachine, EveryStopNeedsANewWarmUp) {
  ReadhesionMachine m = Running(Config());
  Detect(m, kTight, 41);
  ExpectStopped(m.state(), StopReason::kMaxCompensationTime);
  EXPECT_FALSE(m.state().trusted);
  Predicates bal = In(false);
  bal.balise = true;
  bal.tg_moving = true;
  ExpectStopped(Cycle(m, bal), StopReason::kMaxCompensationTime);
  for (int k = 0; k < kWarmup; ++k) Cycle(m, In(false));
  EXPECT_EQ(Cycle(m, bal).mode, Mode::kTg);

  ReadhesionMachine f(Config());
  Predicates failed = In(false);
  failed.imu_ok = false;
  ExpectStopped(Cycle(f, failed), StopReason::kImuFailure);
  for (int k = 0; k < kWarmup; ++k) ExpectStopped(Cycle(f, In(false)), StopReason::kImuFailure);
  EXPECT_TRUE(f.state().trusted);
  bal.tg_moving = false;
  EXPECT_EQ(Cycle(f, bal).mode, Mode::kTg);
}

// Step 4/5: a balise in TG odometry resets the accumulated error (and does not break a
// run of deviations); while compensating it does not reset and the compensation goes on.
// @verifies REQ-RA-012
// @verifies REQ-RA-003
TEST(OdometryReadhesionMachine, BaliseResetsInTgOdometryOnly) {
  ReadhesionMachine m = Running(Config());
  Predicates p = In(false);
  p.balise = true;
  EXPECT_TRUE(Cycle(m, p).balise_reset);
  EXPECT_FALSE(Cycle(m, In(false)).balise_reset);
  Cycle(m, In(true));
  p.deviation = true;
  EXPECT_EQ(Cycle(m, p).deviation_count, 2);
  const MachineState& d = Cycle(m, p);
  EXPECT_TRUE(d.detected);
  EXPECT_TRUE(d.balise_reset);
  const MachineState& s = Cycle(m, p);
  EXPECT_EQ(s.mode, Mode::kCompensating);
  EXPECT_FALSE(s.balise_reset);
  EXPECT_EQ(s.candidates[0].age_cycles, kStartAge + 1);
}

// The cycle allocates nothing (runtime rules: no heap after construction).
TEST(OdometryReadhesionMachine, StepAllocatesNothing) {
  ReadhesionMachine m = Running(Config());
  railproof::testing::StartCountingAllocations();
  Detect(m);
  for (int k = 0; k < 300; ++k) {
    (void)m.Step(In(k % 3 != 0, k % 7 == 0 ? kTight : kNormal, k % 2 == 0, k % 5 == 0));
  }
  EXPECT_EQ(railproof::testing::StopCountingAllocations(), 0U);
  EXPECT_EQ(m.state().mode, Mode::kStopped);
}

}  // namespace
}  // namespace railproof::ra
