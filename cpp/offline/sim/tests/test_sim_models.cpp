// Unit tests of the simulation's models: the seeded channel and the sensor model (the
// train-motion model is tested in offline/common).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/odometry.hpp"
#include "railproof/sim/channel.hpp"
#include "railproof/sim/sensors.hpp"

namespace railproof::sim {
namespace {

// ---- channel ---------------------------------------------------------------------------

std::vector<std::uint8_t> Bytes(std::size_t n, std::uint8_t fill) { return std::vector<std::uint8_t>(n, fill); }

struct Trace {
  std::vector<std::int64_t> due;
  std::uint64_t lost = 0;
};

enum class Other { kSent, kBlocked, kAbsent };  // what train 9's link does

Trace RunChannel(std::uint64_t seed, Other other) {
  Channel ch(ChannelConfig{0.1, 20, 400, 0.0}, seed);
  Trace tr;
  for (std::int64_t t = 0; t < 20'000; t += 100) {
    const auto b = Bytes(66, static_cast<std::uint8_t>(t));
    if (other != Other::kAbsent) {
      ch.Send(9, Direction::kUplink, t, b, other == Other::kBlocked);
    }
    ch.Send(2, Direction::kDownlink, t, b, false);
    for (const Frame& f : ch.Deliver(t)) {
      if (f.train == 2) {
        tr.due.push_back(f.due_ms);
      }
    }
  }
  tr.lost = ch.Stats(Direction::kDownlink).lost_random;
  return tr;
}

TEST(SimChannel, IsDeterministicForASeed) {
  const Trace a = RunChannel(42, Other::kSent);
  const Trace b = RunChannel(42, Other::kSent);
  const Trace c = RunChannel(43, Other::kSent);
  EXPECT_EQ(a.due, b.due);
  EXPECT_EQ(a.lost, b.lost);
  EXPECT_NE(a.due, c.due);
  // a radio-loss window on train 9's link draws nothing from the PRNG: train 2's link sees
  // the same losses and delays as if train 9 sent nothing at all
  const Trace blocked = RunChannel(42, Other::kBlocked);
  const Trace absent = RunChannel(42, Other::kAbsent);
  EXPECT_EQ(blocked.due, absent.due);
  EXPECT_EQ(blocked.lost, absent.lost);
  Prng p1(5);
  Prng p2(5);
  for (int k = 0; k < 100; ++k) {
    EXPECT_EQ(p1.Next(), p2.Next());
  }
}

TEST(SimChannel, LosesAndDelaysAsConfigured) {
  Channel ch(ChannelConfig{0.2, 100, 300, 0.0}, 7);
  const int n = 20'000;
  std::uint64_t delivered = 0;
  for (int k = 0; k < n; ++k) {
    ch.Send(2, Direction::kUplink, k * 10, Bytes(66, 1), false);
  }
  std::int64_t prev_due = -1;
  for (const Frame& f : ch.Deliver(1'000'000)) {
    const std::int64_t delay = f.due_ms - f.sent_ms;
    EXPECT_GE(delay, 100);
    EXPECT_LE(delay, 300);
    EXPECT_GE(f.due_ms, prev_due);  // delivered in due order
    prev_due = f.due_ms;
    ++delivered;
  }
  const auto& st = ch.Stats(Direction::kUplink);
  EXPECT_EQ(st.sent, static_cast<std::uint64_t>(n));
  EXPECT_EQ(st.lost_random + delivered, static_cast<std::uint64_t>(n));
  // 0.2 * 20000 = 4000 expected, sd = sqrt(n p (1-p)) ~ 57: accept 5 sd
  EXPECT_NEAR(static_cast<double>(st.lost_random), 4000.0, 300.0);
  EXPECT_EQ(ch.InFlight(), 0U);
  // a blocked (radio loss) frame is dropped and counted apart
  EXPECT_FALSE(ch.Send(2, Direction::kUplink, 0, Bytes(66, 1), true));
  EXPECT_EQ(ch.Stats(Direction::kUplink).lost_fault, 1U);
  // purge drops a train's frames in flight
  ch.Send(3, Direction::kDownlink, 0, Bytes(66, 1), false);
  ch.Purge(3);
  EXPECT_EQ(ch.InFlight(), 0U);
}

TEST(SimChannel, CorruptedFramesAreCorrectedOrRejectedByTheFrameDecoder) {
  // real frames: up to 8 symbol errors in a block are corrected, more are detected
  tg::TelegramHeader h{};
  h.version = tg::kVersion;
  h.type = tg::TelegramType::kPosition;
  h.src = 2;
  h.dst = 1;
  h.seq = 1;
  const std::vector<std::uint8_t> payload(40, 0x5A);
  const std::array<std::uint8_t, tg::kKeyBytes> kb{};
  const tg::LinkKey key(kb);
  tg::EncodedFrame frame{};
  ASSERT_EQ(tg::EncodeFrame(h, payload, key, frame), tg::EncodeStatus::kOk);
  Channel ch(ChannelConfig{0.0, 0, 0, 1.0}, 11);
  int corrected = 0;
  int rejected = 0;
  for (int k = 0; k < 400; ++k) {
    ch.Send(2, Direction::kUplink, k, frame.View(), false);
  }
  for (const Frame& f : ch.Deliver(1'000)) {
    ASSERT_GE(f.corrupted_symbols, 1U);
    ASSERT_LE(f.corrupted_symbols, 12U);
    tg::DecodedFrame out{};
    const auto r = tg::DecodeFrame(f.bytes, out);
    if (f.corrupted_symbols <= 8) {
      EXPECT_EQ(r, tg::RejectReason::kNone);
      ++corrected;
    } else {
      EXPECT_NE(r, tg::RejectReason::kNone);
      ++rejected;
    }
  }
  EXPECT_GT(corrected, 0);
  EXPECT_GT(rejected, 0);
  EXPECT_EQ(ch.Stats(Direction::kUplink).corrupted, 400U);
}

// ---- sensors ---------------------------------------------------------------------------

// The warm-up at standstill the odometry needs after its start (REQ-RA-015).
constexpr int kWarmupCycles =
    static_cast<int>((params::ra::moving_average_ms + params::ra::tg_window_ms) / params::ra::cycle_ms);

// A train on a level line with its odometry fed by the sensor model: it stands for the
// odometry's warm-up, accelerates, cruises over a balise, brakes to a stop. Every cycle's data
// is accepted, the position stays valid with no stop demand, and the true front lies inside
// the odometry's envelope at every cycle.
// @verifies REQ-RA-013 REQ-RA-015
TEST(SimSensors, TheOdometryTracksTheTrueMotionInsideItsEnvelope) {
  const std::array<ra::OdometrySection, 1> level = {{{0, 20'000'000, 0, 10'000, 0}}};
  ra::OdometryConfig oc;
  oc.train_length_mm = 60'000;
  oc.sections = level.data();
  oc.section_count = 1;
  oc.initial_front_mm = 1'000'000;
  auto od = std::make_unique<ra::Odometry>();
  ASSERT_EQ(ra::Odometry::Create(oc, *od), ra::ConfigError::kNone);
  for (const std::uint64_t seed : {1U, 2U, 3U}) {
    SensorConfig sc;
    sc.seed = seed;
    SensorModel sensors(sc);
    EXPECT_LE(std::abs(sensors.diameter_error()), 0.9e-3);
    ASSERT_EQ(ra::Odometry::Create(oc, *od), ra::ConfigError::kNone);
    offline::Motion truth{1000.0, 0.0};
    std::int64_t t = 0;
    double worst_outside = 0.0;
    bool balise_passed = false;
    for (int k = 0; k < 1200; ++k) {  // 120 s
      t += 100;
      const double a = k < 60 ? 0.0 : (k < 260 ? 0.5 : (k < 900 ? 0.0 : -0.8));
      TrueCycle c{t, truth, a, 0.0, std::nullopt, std::nullopt};
      const offline::Motion next = offline::Advance(truth, a, 0.1);
      if (!balise_passed && next.position >= 1500.0) {
        balise_passed = true;
        c.balise_mm = 1'500'000;  // the fix of the balise the front passed (the odometry's reference point)
      }
      const ra::OdometryOutput& o = od->Step(sensors.Cycle(c));
      truth = next;
      ASSERT_EQ(o.input_error, ra::InputError::kNone) << "seed " << seed << " cycle " << k;
      if (k < kWarmupCycles) {
        continue;  // start-up: the odometry trusts its history after the warm-up (REQ-RA-015)
      }
      ASSERT_TRUE(o.position_valid) << "seed " << seed << " cycle " << k;
      EXPECT_FALSE(o.stop_demand) << "seed " << seed << " cycle " << k;
      const double lo = static_cast<double>(o.front_mm) / 1000.0 - static_cast<double>(o.rear_error_mm) / 1000.0;
      const double hi = static_cast<double>(o.front_mm + o.front_error_mm) / 1000.0;
      worst_outside = std::max({worst_outside, lo - truth.position, truth.position - hi});
    }
    EXPECT_TRUE(balise_passed);
    EXPECT_EQ(truth.speed, 0.0);
    EXPECT_LE(worst_outside, 0.0) << "seed " << seed << ": the true front left the envelope by " << worst_outside << " m";
    EXPECT_GT(truth.position, 1500.0);
  }
}

// The streams follow the true motion: the pulse count is the wheel's distance over its true
// pulse length, the last edge lies in the cycle, and the IMU reads gravity on a gradient.
TEST(SimSensors, StreamsFollowTheTrueMotion) {
  SensorConfig sc;
  sc.imu_noise_mps2 = 0.0;
  sc.imu_rate_noise_rad_s = 0.0;
  SensorModel s(sc);
  const offline::Motion m{0.0, 10.0};
  const ra::CycleInput in = s.Cycle(TrueCycle{100, m, 0.0, 20.0, std::nullopt, std::nullopt});
  EXPECT_EQ(in.tg.pulses, static_cast<std::int64_t>(std::floor(1.0 / s.true_pulse_m())));
  EXPECT_GT(in.tg.last_edge_us, 0);
  EXPECT_LE(in.tg.last_edge_us, 100'000);
  EXPECT_NEAR(in.imu[0].ax, offline::kGravity * std::sin(std::atan(0.02)), 1e-12);
  EXPECT_EQ(in.imu[9].time_us, 100'000);
  EXPECT_NEAR(s.nominal_pulse_m(), 3.14159265 * 0.86 / 90.0, 1e-6);
}

}  // namespace
}  // namespace railproof::sim
