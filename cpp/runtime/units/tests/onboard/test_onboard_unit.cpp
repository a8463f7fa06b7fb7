// The on-board unit as a unit: configuration errors, the start-up, the position report built
// from the envelope, the governing limit, the merged restrictions in the supervision, the
// bundles sent and received, typed statuses of rejected inputs, no heap in the cycle,
// determinism. Among them the tests that kill the glue's seeded faults (FAULT_UNIT_*).
#include <gtest/gtest.h>

#include <algorithm>
#include <variant>
#include <vector>

#include "onboard_rig.hpp"
#include "railproof/testing/alloc_counter.hpp"

namespace railproof::units::test {
namespace {

OnboardConfigError CreateError(const OnboardConfig& c) { return OnboardUnit::Create(c).check.error; }

TEST(OnboardUnitConfig, AcceptsTheTestLine) {
  const Line line;
  const auto r = OnboardUnit::Create(Config(line));
  EXPECT_EQ(r.check.error, OnboardConfigError::kNone);
  EXPECT_TRUE(r.unit.has_value());
}

TEST(OnboardUnitConfig, RefusesEachBadPartWithItsReason) {
  const Line line;
  {
    OnboardConfig c = Config(line);
    c.radio_period_ms = 150;
    EXPECT_EQ(CreateError(c), OnboardConfigError::kPeriods);
    c = Config(line);
    c.radio_offset_ms = c.radio_period_ms + kOnboardCycleMs;
    EXPECT_EQ(CreateError(c), OnboardConfigError::kPeriods);
  }
  {
    Line bad;
    bad.blocks[3] = bad.blocks[2];
    const auto r = OnboardUnit::Create(Config(bad));
    EXPECT_EQ(r.check.error, OnboardConfigError::kBlocks);
    EXPECT_EQ(r.check.entry, 3U);
    EXPECT_FALSE(r.unit.has_value());
  }
  {
    Line bad;
    bad.balises.push_back({7, 3'000'000});
    const auto r = OnboardUnit::Create(Config(bad));
    EXPECT_EQ(r.check.error, OnboardConfigError::kBalises);
    EXPECT_EQ(r.check.entry, 2U);
  }
  {
    OnboardConfig c = Config(line);
    c.odometry.wheel_diameter_um = 100;
    const auto r = OnboardUnit::Create(c);
    EXPECT_EQ(r.check.error, OnboardConfigError::kOdometry);
    EXPECT_EQ(r.check.odometry, ra::ConfigError::kWheelDiameter);
  }
  {
    OnboardConfig c = Config(line);
    c.train.beta_n7_mm_s2 = c.train.beta_e_mm_s2 + 1;
    const auto r = OnboardUnit::Create(c);
    EXPECT_EQ(r.check.error, OnboardConfigError::kTrainData);
    EXPECT_EQ(r.check.braking, br::CreateError::kServiceAboveEmergency);
  }
  {
    Line bad;
    bad.limits = {{0, 5'000'000, 20'000}, {4'000'000, 10'000'000, 10'000}};
    const auto r = OnboardUnit::Create(Config(bad));
    EXPECT_EQ(r.check.error, OnboardConfigError::kLineProfile);
    EXPECT_EQ(r.check.profile.verdict, br::ProfileVerdict::kOverlap);
    EXPECT_TRUE(r.check.profile.in_restrictions);
  }
  {
    // more line limits than a profile merged with every restriction the train can hold fits
    Line big;
    big.limits.clear();
    const auto n = static_cast<std::int64_t>(core::kMaxProfileCapacity / 2);
    for (std::int64_t i = 0; i < n; ++i) {
      big.limits.push_back({i * 1'000, (i + 1) * 1'000, 20'000});
    }
    const auto r = OnboardUnit::Create(Config(big));
    EXPECT_EQ(r.check.error, OnboardConfigError::kLineProfile);
    EXPECT_EQ(r.check.profile.verdict, br::ProfileVerdict::kTooManyRestrictions);
  }
  {
    Line bad;
    bad.crossings.push_back({6, 2'000'000, 2'010'000, 30'000});
    const auto r = OnboardUnit::Create(Config(bad));
    EXPECT_EQ(r.check.error, OnboardConfigError::kCrossings);
    EXPECT_EQ(r.check.crossings, lc::onboard::ProtectionError::kCrossingUnsorted);
  }
  {
    OnboardConfig c = Config(line);
    c.link_key.reset();
    EXPECT_EQ(CreateError(c), OnboardConfigError::kRadio);
    c = Config(line);
    c.radio.role = tg::Role::kGround;
    EXPECT_EQ(CreateError(c), OnboardConfigError::kRadio);
    c = Config(line);
    c.radio.peer_id = c.radio.own_id;
    const auto r = OnboardUnit::Create(c);
    EXPECT_EQ(r.check.error, OnboardConfigError::kRadio);
    EXPECT_EQ(r.check.radio, tg::ConfigError::kSameIds);
  }
}

TEST(OnboardUnit, StartUpBrakesUntilLinkAuthorityAndReset) {
  const Line line;
  Rig rig(Config(line));
  const OnboardOutputs& first = rig.Step();
  EXPECT_EQ(first.brake, BrakeDemand::kEmergency);
  EXPECT_EQ(first.reason, BrakeReason::kRadioLink);
  EXPECT_TRUE(first.sent);  // the first telegram at the first cycle (offset 0)
  // nothing to echo yet: the ground refuses it but learns its sequence number
  EXPECT_EQ(rig.Ground().Last().reason, tg::RejectReason::kNoEcho);
  rig.Answer(messages::KeepAlive{});
  EXPECT_EQ(rig.Step().link, tg::LinkState::kUp);
  EXPECT_EQ(rig.Unit().Outputs().reason, BrakeReason::kOdometryStop);  // the warm-up
  rig.StepToSend();
  ASSERT_EQ(rig.Heard().size(), 1U);
  EXPECT_TRUE(std::holds_alternative<messages::NoPosition>(rig.Heard()[0]));
  for (int k = 0; k < ra::test::kWarmupCycles; ++k) {
    rig.Step();
  }
  EXPECT_TRUE(rig.Unit().Outputs().position_valid);
  rig.StepToSend();
  rig.Answer(messages::KeepAlive{});
  const OnboardOutputs& up = rig.Step();
  EXPECT_EQ(up.link, tg::LinkState::kUp);
  EXPECT_EQ(up.brake, BrakeDemand::kEmergency);
  rig.Step();
  EXPECT_EQ(rig.Unit().Outputs().reason, BrakeReason::kNoUsableLimit);
  rig.Start(2'500'000);
  const OnboardOutputs& run = rig.Step();
  EXPECT_EQ(run.brake, BrakeDemand::kNone) << ToString(run.reason);
  EXPECT_TRUE(run.authority_usable);
  EXPECT_EQ(run.indications.limit_kind, LimitKind::kMovementAuthority);
  EXPECT_EQ(run.indications.obstruction, messages::Obstruction::kPrecedingTrain);
  EXPECT_GT(run.indications.permitted_speed_mm_s, 0);
}

TEST(OnboardUnit, ReportsTheNominalFrontAsBlockAndOffsetWithTheEnvelopeCorrection) {
  const Line line;
  Rig rig(Config(line));
  rig.Start(4'000'000);
  const OnboardOutputs& out = rig.StepToSend();
  ASSERT_TRUE(out.sent);
  ASSERT_FALSE(rig.Heard().empty());
  const auto* rep = std::get_if<messages::PositionReport>(&rig.Heard()[0]);
  ASSERT_NE(rep, nullptr);
  const ra::OdometryOutput& o = rig.Unit().Odometry();
  ASSERT_GT(ra::ReportCorrectionMm(o), 0);
  EXPECT_EQ(rep->train_id, kTrainId);
  EXPECT_EQ(line.blocks[rep->front_block] + rep->offset_mm, o.front_mm);
  EXPECT_GT(rep->offset_mm, 0);  // the block holding the foremost millimetre
  EXPECT_EQ(rep->correction_mm, ra::ReportCorrectionMm(o));
  EXPECT_EQ(rep->length_mm, ra::test::kTrainLengthMm);
  EXPECT_EQ(rep->last_balise_mm, o.last_balise_mm);
  EXPECT_EQ(rep->speed_mm_s, o.speed_mm_s);
}

TEST(OnboardUnit, SupervisesTheSafeFrontOfTheEnvelope) {
  const Line line;
  OnboardConfig c = Config(line);
  Rig rig(c);
  rig.Start(1'500'000);
  const OnboardOutputs& out = rig.Step();
  const ra::OdometryOutput& o = rig.Unit().Odometry();
  ASSERT_GT(o.front_error_mm + o.rear_error_mm, 0);
  EXPECT_EQ(out.indications.target_distance_mm, 1'500'000 - (o.front_mm + o.front_error_mm));
  // the braking module fed the envelope directly gives the same permitted speed
  auto calc = br::PatternCalculator::Create(c.train, c.supervision);
  ASSERT_EQ(calc.calculator->SetProfile(line.gradients, line.limits).verdict, br::ProfileVerdict::kAccept);
  const br::Evaluation e = calc.calculator->Evaluate(ra::ToPositionEstimate(o), 1'500'000);
  EXPECT_EQ(out.indications.permitted_speed_mm_s, std::max<std::int64_t>(0, e.speeds.v_7n));
}

TEST(OnboardUnit, TheNearerOfAuthorityAndCrossingLimitGoverns) {
  const Line line;  // crossing 5 at [3000 m, 3010 m)
  Rig rig(Config(line));
  rig.Start(2'500'000);
  EXPECT_EQ(rig.Step().indications.limit_kind, LimitKind::kMovementAuthority);
  EXPECT_EQ(rig.Unit().Outputs().indications.limit_mm, 2'500'000);
  for (int k = 0; k < 3; ++k) {
    rig.StepToSend();
    rig.Answer(StopLimit(4'000'000, rig.Now()));
    rig.Step();
  }
  const OnboardOutputs& out = rig.Step();
  const auto protection = rig.Unit().Crossings().Output().stop_limit_mm;
  ASSERT_TRUE(protection.has_value());
  EXPECT_LT(*protection, 3'000'000);
  EXPECT_EQ(out.indications.limit_kind, LimitKind::kCrossingProtection);
  EXPECT_EQ(out.indications.limit_mm, protection);
  EXPECT_EQ(out.indications.crossing_id, 5U);
}

TEST(OnboardUnit, HeldRestrictionsReachTheBrakingProfile) {
  const Line line;
  Rig rig(Config(line));
  const messages::SpeedRestriction near{11, 900'000, 1'200'000, 5'000};
  const messages::SpeedRestriction far{12, 2'000'000, 2'500'000, 8'000};
  rig.Start(4'000'000, {near, far});
  rig.Step();
  const auto p = rig.Unit().Profile();
  const auto has = [&](std::int64_t b, std::int64_t e, std::int64_t v) {
    return std::any_of(p.begin(), p.end(), [&](const core::RestrictionSegment& s) {
      return s.begin_mm == b && s.end_mm == e && s.limit_mm_s == v;
    });
  };
  EXPECT_TRUE(has(900'000, 1'200'000, 5'000));  // the train is inside it
  EXPECT_TRUE(has(2'000'000, 2'500'000, 8'000));
  EXPECT_TRUE(has(1'200'000, 2'000'000, 20'000));
  // inside the restriction the permitted speed is below it
  EXPECT_LE(rig.Unit().Outputs().indications.permitted_speed_mm_s, 5'000);
}

TEST(OnboardUnit, ReportsEveryRejectedInputWithItsReason) {
  const Line line;
  Rig rig(Config(line));
  rig.Start(4'000'000);
  rig.StepToSend();
  std::vector<std::uint8_t> corrupt = rig.Ground().Send(rig.Now(), std::vector<messages::Message>{messages::KeepAlive{}});
  ASSERT_GE(corrupt.size(), 66U);
  for (std::size_t i = 0; i < 9; ++i) {  // 9 symbols of the first RS block: beyond correction
    corrupt[i * 7] ^= 0xA5;
  }
  rig.Deliver(corrupt);
  const messages::Message other = StopLimit(4'000'000, rig.Now(), {}, kTrainId + 1);
  const messages::Message report = messages::PositionReport{kTrainId, 0, 0, 1, 0, 0, 0, messages::Direction::kNominal};
  rig.Answer(std::vector<messages::Message>{other, report, messages::WithdrawalAck{5, kTrainId + 1}});
  rig.Balise(99);
  const OnboardOutputs& out = rig.Step();
  EXPECT_TRUE(out.unknown_balise);
  const auto ev = out.Events();
  ASSERT_EQ(ev.size(), 4U);
  EXPECT_EQ(ev[0].status, RxStatus::kFrameRejected);
  EXPECT_EQ(ev[0].reject, tg::RejectReason::kRsUncorrectable);
  EXPECT_EQ(ev[1].status, RxStatus::kOtherTrain);
  EXPECT_EQ(ev[1].type, messages::MessageType::kStopLimit);
  EXPECT_EQ(ev[2].status, RxStatus::kUnexpectedType);
  EXPECT_EQ(ev[2].type, messages::MessageType::kPositionReport);
  EXPECT_EQ(ev[3].status, RxStatus::kOtherTrain);
  EXPECT_EQ(ev[3].entry, 2U);
  // an old stop limit: refused by the authority with its verdict
  rig.StepToSend();
  rig.Answer(StopLimit(5'000'000, rig.Now() - 10'000));
  const OnboardOutputs& old = rig.Step();
  ASSERT_EQ(old.Events().size(), 1U);
  EXPECT_EQ(old.Events()[0].status, RxStatus::kStopLimitRefused);
  EXPECT_EQ(old.Events()[0].verdict, mb::onboard::Verdict::kTooOld);
  EXPECT_EQ(old.authority_limit_mm, 4'000'000);
}

TEST(OnboardUnit, UndecodablePayloadAndTooManyFramesAreReported) {
  const Line line;
  Rig rig(Config(line));
  rig.StepToSend();
  // a payload the telegram layer accepts but the codec does not: one unknown type byte
  tg::EncodedFrame f{};
  tg::Endpoint ground;
  tg::EndpointConfig g = tg::DeploymentConfig(tg::Role::kGround, kGroundId, static_cast<std::uint16_t>(kTrainId));
  ASSERT_EQ(ground.Init(g, tg::LinkKey(kKey)), tg::ConfigError::kNone);
  const std::array<std::uint8_t, 1> junk{0xEE};
  ground.Cycle(static_cast<std::uint32_t>(rig.Now()), junk, f);
  for (std::size_t k = 0; k < kMaxFramesPerCycle + 2; ++k) {
    rig.Deliver({f.View().begin(), f.View().end()});
  }
  const OnboardOutputs& out = rig.Step();
  const auto ev = out.Events();
  ASSERT_EQ(ev.size(), kMaxFramesPerCycle + 1);
  EXPECT_EQ(ev[0].status, RxStatus::kFrameRejected);  // no echo of the train's telegram yet
  EXPECT_EQ(ev[0].reject, tg::RejectReason::kNoEcho);
  EXPECT_EQ(ev[kMaxFramesPerCycle].status, RxStatus::kFramesDropped);
  EXPECT_EQ(ev[kMaxFramesPerCycle].entry, 2U);
  // through the rig's ground, which has heard the train: the codec's reason
  rig.StepToSend();
  rig.Deliver(rig.Ground().SendBytes(rig.Now(), junk));
  const OnboardOutputs& undecodable = rig.Step();
  ASSERT_EQ(undecodable.Events().size(), 1U);
  EXPECT_EQ(undecodable.Events()[0].status, RxStatus::kUndecodable);
  EXPECT_EQ(undecodable.Events()[0].decode, messages::DecodeError::kUnknownType);
}

TEST(OnboardUnit, SendsCrossingRequestsAfterTheReportInOneBundle) {
  Line line;
  line.crossings = {{5, 1'300'000, 1'310'000, 30'000}, {6, 1'400'000, 1'410'000, 30'000}};
  Rig rig(Config(line));
  rig.Start(4'000'000);
  rig.StepToSend();
  rig.StepToSend();
  const auto& heard = rig.Heard();
  ASSERT_EQ(heard.size(), 3U);
  EXPECT_TRUE(std::holds_alternative<messages::PositionReport>(heard[0]));
  const auto* r5 = std::get_if<messages::CrossingRequest>(&heard[1]);
  const auto* r6 = std::get_if<messages::CrossingRequest>(&heard[2]);
  ASSERT_NE(r5, nullptr);
  ASSERT_NE(r6, nullptr);
  EXPECT_EQ(r5->crossing_id, 5U);
  EXPECT_EQ(r6->crossing_id, 6U);
  EXPECT_EQ(r5->train_id, kTrainId);
  EXPECT_EQ(rig.Unit().Outputs().crossing_messages_sent, 2U);
}

TEST(OnboardUnit, CrossingMessagesBeyondOneTelegramFollowInTheNext) {
  Line line;
  line.crossings.clear();
  for (std::uint32_t i = 0; i < 10; ++i) {
    const std::int64_t at = 1'100'000 + 20'000 * static_cast<std::int64_t>(i);
    line.crossings.push_back({100 + i, at, at + 5'000, 30'000});
  }
  Rig rig(Config(line));
  rig.Start(4'000'000);
  std::vector<std::uint32_t> ids;
  for (int t = 0; t < 2; ++t) {
    rig.StepToSend();
    ASSERT_FALSE(rig.Heard().empty());
    EXPECT_TRUE(std::holds_alternative<messages::PositionReport>(rig.Heard()[0]));
    for (std::size_t k = 1; k < rig.Heard().size(); ++k) {
      ids.push_back(std::get<messages::CrossingRequest>(rig.Heard()[k]).crossing_id);
    }
  }
  // a report and 7 requests fill one bundle; the others lead the next one
  ASSERT_EQ(ids.size(), 14U);
  for (std::size_t k = 1; k < ids.size(); ++k) {
    EXPECT_EQ(ids[k], 100 + (ids[k - 1] - 100 + 1) % 10) << k;
  }
}

TEST(OnboardUnit, CycleAllocatesNothing) {
  const Line line;
  Rig rig(Config(line));
  rig.Start(4'000'000);
  OnboardInputs in;
  in.sensors = rig.Sensors().Next();
  in.now_ms = in.sensors.time_ms;
  testing::StartCountingAllocations();
  for (int k = 0; k < 30; ++k) {
    (void)rig.Unit().Cycle(in);
    in.sensors = rig.Sensors().Next();
    in.now_ms = in.sensors.time_ms;
  }
  EXPECT_EQ(testing::StopCountingAllocations(), 0U);
}

TEST(OnboardUnit, SameInputsGiveTheSameOutputsAndBytes) {
  const Line line;
  Rig a(Config(line));
  Rig b(Config(line));
  a.Start(4'000'000);
  b.Start(4'000'000);
  for (int k = 0; k < 25; ++k) {
    const OnboardOutputs& x = a.Step({0.5, 0.0}, ra::test::ImuValues{0.5, 0, ra::test::kG, 0, 0, 0});
    const OnboardOutputs& y = b.Step({0.5, 0.0}, ra::test::ImuValues{0.5, 0, ra::test::kG, 0, 0, 0});
    ASSERT_EQ(x.sent, y.sent);
    EXPECT_TRUE(std::equal(x.frame.View().begin(), x.frame.View().end(), y.frame.View().begin(), y.frame.View().end()));
    EXPECT_EQ(x.front_mm, y.front_mm);
    EXPECT_EQ(x.brake, y.brake);
    EXPECT_EQ(x.indications.permitted_speed_mm_s, y.indications.permitted_speed_mm_s);
  }
}

}  // namespace
}  // namespace railproof::units::test
