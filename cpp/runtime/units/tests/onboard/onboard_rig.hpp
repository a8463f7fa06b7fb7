// Test rig of the on-board unit: a line, a train, the unit fed by a synthetic sensor stream
// (the odometry tests' ra::test::Stream) and the ground's end of the radio link (a tg
// endpoint in the ground role and the codec), as a simulator would drive it: one Cycle every
// 100 ms, the ground's telegrams delivered in the next cycle.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "ra/tests/test_odometry_util.hpp"
#include "railproof/messages/codec.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/units/onboard_unit.hpp"

namespace railproof::units::test {

inline constexpr std::array<std::uint8_t, tg::kKeyBytes> kKey = {
    0x6f, 0x6e, 0x62, 0x6f, 0x61, 0x72, 0x64, 0x2d, 0x75, 0x6e, 0x69, 0x74, 0x2d, 0x6b, 0x65, 0x79,
    0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x1b, 0x1c, 0x1d, 0x1e, 0x1f};
inline constexpr std::uint16_t kGroundId = 1;
inline constexpr std::uint32_t kTrainId = 42;

// A 10 km line of 100 m blocks, level but for a falling stretch, a line limit of 20 m/s,
// two balises and one crossing at 3 km.
struct Line {
  std::vector<std::int64_t> blocks;
  std::vector<core::GradientSegment> gradients{{5'000'000, 6'000'000, -50}};
  std::vector<core::RestrictionSegment> limits{{0, 10'000'000, 20'000}};
  std::vector<BaliseEntry> balises{{7, ra::test::kInitialFrontMm}, {8, 2'000'000}};
  std::vector<lc::CrossingData> crossings{{5, 3'000'000, 3'010'000, 30'000}};
  std::vector<ra::OdometrySection> sections = ra::test::LevelLine();
  Line() {
    for (std::int64_t b = 0; b <= 10'000'000; b += 100'000) {
      blocks.push_back(b);
    }
  }
};

inline br::TrainData Train() {
  return br::TrainData{.length_mm = ra::test::kTrainLengthMm,
                       .accel_max_mm_s2 = 1'000,
                       .beta_e_mm_s2 = 1'100,
                       .beta_n7_mm_s2 = 900,
                       .emergency_free_running_ms = 1'500,
                       .service_free_running_ms = 2'500,
                       .overspeed_mm_s = 2'778,
                       .speed_error_ppm = 20'000,
                       .speed_error_abs_mm_s = 200};
}

inline OnboardConfig Config(const Line& line) {
  OnboardConfig c;
  c.train_id = kTrainId;
  c.train = Train();
  c.odometry = ra::test::Config(line.sections);
  c.initial_front_mm = ra::test::kInitialFrontMm;
  c.line = LineData{line.blocks, line.gradients, line.limits, line.balises, line.crossings, line.sections};
  c.radio = tg::DeploymentConfig(tg::Role::kTrain, static_cast<std::uint16_t>(kTrainId), kGroundId);
  c.link_key.emplace(kKey);
  return c;
}

// The ground's end of the link: frames the messages it is given, reads the unit's telegrams.
class Peer {
 public:
  explicit Peer(const tg::EndpointConfig& train_side) {
    tg::EndpointConfig g = train_side;
    g.role = tg::Role::kGround;
    std::swap(g.own_id, g.peer_id);
    EXPECT_EQ(ep_.Init(g, tg::LinkKey(kKey)), tg::ConfigError::kNone);
  }
  // One ground telegram carrying `messages` (bundled), or nothing if the layer sends nothing.
  std::vector<std::uint8_t> Send(std::int64_t now_ms, std::span<const messages::Message> m) {
    const messages::Encoded e = messages::EncodeBundle(m);
    EXPECT_TRUE(e.Ok()) << messages::ToString(e.error);
    return SendBytes(now_ms, e.payload.View());
  }
  std::vector<std::uint8_t> SendBytes(std::int64_t now_ms, std::span<const std::uint8_t> payload) {
    tg::EncodedFrame f{};
    ep_.Cycle(static_cast<std::uint32_t>(now_ms), payload, f);
    const auto v = f.View();
    return {v.begin(), v.end()};
  }
  // Reads a telegram of the unit; its messages, empty if rejected.
  std::vector<messages::Message> Hear(std::int64_t now_ms, std::span<const std::uint8_t> frame) {
    std::array<std::uint8_t, tg::kPayloadMax> payload{};
    last_ = ep_.Receive(static_cast<std::uint32_t>(now_ms), frame, payload);
    if (last_.reason != tg::RejectReason::kNone) {
      return {};
    }
    const auto d = messages::DecodeBundle(std::span<const std::uint8_t>(payload).first(last_.header.payload_len));
    EXPECT_TRUE(d.Ok()) << messages::ToString(d.error);
    const auto v = d.bundle.View();
    return {v.begin(), v.end()};
  }
  [[nodiscard]] const tg::Endpoint::RxResult& Last() const { return last_; }

 private:
  tg::Endpoint ep_;
  tg::Endpoint::RxResult last_{};
};

inline messages::StopLimitTelegram StopLimit(std::int64_t limit_mm, std::int64_t issue_ms,
                                             std::vector<messages::SpeedRestriction> tsr = {},
                                             std::uint32_t train = kTrainId) {
  messages::StopLimitTelegram t{};
  t.train_id = train;
  t.limit_mm = limit_mm;
  t.kind = messages::Obstruction::kPrecedingTrain;
  t.issue_time_ms = issue_ms;
  t.restriction_count = static_cast<std::uint32_t>(tsr.size());
  for (std::size_t i = 0; i < tsr.size() && i < t.restrictions.size(); ++i) {
    t.restrictions[i] = tsr[i];
  }
  return t;
}

// The unit, its sensor stream and its ground. Each Step is one on-board cycle; the frames
// queued with Deliver reach the unit in the next one; every telegram the unit sends is read
// by the peer (Heard).
class Rig {
 public:
  explicit Rig(const OnboardConfig& c, std::int64_t t0_ms = 1'000) : peer_(c.radio), stream_(0.0, t0_ms) {
    auto r = OnboardUnit::Create(c);
    EXPECT_EQ(r.check.error, OnboardConfigError::kNone) << ToString(r.check.error);
    unit_.emplace(std::move(*r.unit));
  }
  const OnboardOutputs& Step(const ra::test::Kinematics& k = {}, const ra::test::ImuValues& imu = {}) {
    return StepWith(stream_.Next(k, imu));
  }
  // One cycle on sensor data the caller made (at the time of Sensors().Next()); the faults apply.
  const OnboardOutputs& StepWith(const ra::CycleInput& sensors) {
    OnboardInputs in;
    in.sensors = sensors;
    in.now_ms = in.sensors.time_ms;
    if (imu_fault) {
      in.sensors.imu_count = static_cast<std::uint8_t>(ra::kImuSamplesPerCycle - 1);
    }
    if (tg_fault) {
      in.sensors.tg.last_edge_us = in.sensors.tg.time_us + 1;  // an edge after the sample
    }
    in.balise_id = std::exchange(balise_, std::nullopt);
    in.driver = driver_;
    in.dwell_departure_ms = dwell_departure_ms;
    std::vector<std::span<const std::uint8_t>> spans(queued_.begin(), queued_.end());
    in.frames = spans;
    const OnboardOutputs& out = unit_->Cycle(in);
    queued_.clear();
    if (out.sent) {
      heard_ = peer_.Hear(out.now_ms, out.frame.View());
    }
    return out;
  }
  // Steps until a telegram was sent (at most one radio period).
  const OnboardOutputs& StepToSend() {
    for (int k = 0; k < 100; ++k) {
      if (Step().sent) {
        break;
      }
    }
    return unit_->Outputs();
  }
  void Deliver(std::vector<std::uint8_t> frame) { queued_.push_back(std::move(frame)); }
  // The ground's answer to the last telegram: `messages`, for the next cycle.
  void Answer(std::span<const messages::Message> m) { Deliver(peer_.Send(Now(), m)); }
  void Answer(const messages::Message& m) { Answer(std::span<const messages::Message>(&m, 1)); }
  void Balise(std::uint32_t id) { balise_ = id; }
  void Drive(const br::DriverInputs& d) { driver_ = d; }

  // Warm-up at standstill, link up, a stop limit ahead and the brake reset: a train ready
  // to run at Now().
  void Start(std::int64_t limit_mm, std::vector<messages::SpeedRestriction> tsr = {}) {
    for (int k = 0; k < ra::test::kWarmupCycles + 1; ++k) {
      Step();
    }
    for (int k = 0; k < 3; ++k) {
      StepToSend();
      Answer(StopLimit(limit_mm, Now(), tsr));
      Step();
    }
    driver_.handle_emergency = true;
    driver_.reset = true;
    Step();
    Step();
    Step();
    driver_ = {};
  }

  [[nodiscard]] std::int64_t Now() const { return stream_.time_ms(); }
  OnboardUnit& Unit() { return *unit_; }
  [[nodiscard]] const OnboardUnit& Unit() const { return *unit_; }
  Peer& Ground() { return peer_; }
  ra::test::Stream& Sensors() { return stream_; }
  [[nodiscard]] const std::vector<messages::Message>& Heard() const { return heard_; }
  std::optional<std::int64_t> dwell_departure_ms;
  bool imu_fault = false;
  bool tg_fault = false;

 private:
  std::optional<OnboardUnit> unit_;
  Peer peer_;
  ra::test::Stream stream_;
  std::vector<std::vector<std::uint8_t>> queued_;
  std::vector<messages::Message> heard_;
  std::optional<std::uint32_t> balise_;
  br::DriverInputs driver_{};
};

}  // namespace railproof::units::test
