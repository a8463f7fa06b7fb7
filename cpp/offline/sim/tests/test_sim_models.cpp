// Unit tests of the simulation's models: longitudinal dynamics (hand-checked cases),
// supervision curves, the seeded channel.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/sim/channel.hpp"
#include "railproof/offline/dynamics.hpp"

namespace railproof::sim {
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)
namespace {

TrainPerformance NoResistance() {
  TrainPerformance p;
  p.length_m = 100.0;
  p.max_speed_mps = 100.0 / 3.6;
  p.accel_mps2 = 1.0;
  p.service_decel_mps2 = 1.0;
  p.emergency_decel_mps2 = 1.5;
  p.resistance = Resistance{0.0, 0.0, 0.0};
  return p;
}

TEST(SimDynamics, AccelerationFromStandstillMatchesHandCalculation) {
  // a = 1 m/s^2 for 10 s: v = 10 m/s, s = a t^2 / 2 = 50 m (exact integration per step)
  const TrainPerformance p = NoResistance();
  Motion m{0.0, 0.0};
  for (int k = 0; k < 100; ++k) {
    const double a = NetAcceleration(p, Control{1.0, 0.0, false}, m.speed_mps, 0.0);
    m = Advance(m, a, 0.1);
  }
  EXPECT_NEAR(m.speed_mps, 10.0, 1e-9);
  EXPECT_NEAR(m.position_m, 50.0, 1e-9);
}

TEST(SimDynamics, ServiceAndEmergencyBrakingDistancesMatchHandCalculation) {
  // from 20 m/s: service 1 m/s^2 stops in v^2 / 2b = 200 m after 20 s; emergency 1.5 m/s^2
  // in 133.33 m; the train stops and does not roll back
  const TrainPerformance p = NoResistance();
  for (const bool emergency : {false, true}) {
    Motion m{1000.0, 20.0};
    int steps = 0;
    while (m.speed_mps > 0.0 && steps < 1000) {
      const double a = NetAcceleration(p, Control{0.0, 1.0, emergency}, m.speed_mps, 0.0);
      m = Advance(m, a, 0.1);
      ++steps;
    }
    const double b = emergency ? 1.5 : 1.0;
    EXPECT_NEAR(m.position_m - 1000.0, 400.0 / (2.0 * b), 1e-9);
    EXPECT_NEAR(steps * 0.1, 20.0 / b, 0.1 + 1e-9);
    EXPECT_NEAR(StoppingDistance(20.0, b, 0.0), 400.0 / (2.0 * b), 1e-12);
    const Motion still = Advance(m, NetAcceleration(p, Control{0.0, 1.0, emergency}, 0.0, 0.0), 0.1);
    EXPECT_EQ(still.position_m, m.position_m);
    EXPECT_EQ(still.speed_mps, 0.0);
  }
}

TEST(SimDynamics, ResistanceGradientAndLimits) {
  TrainPerformance p = NoResistance();
  p.resistance = Resistance{1.5, 0.02, 0.0003};
  // r(100 km/h) = 1.5 + 2 + 3 = 6.5 N/kN -> 9.81 * 6.5 / 1000 m/s^2
  EXPECT_NEAR(ResistanceDecel(p.resistance, 100.0 / 3.6), 9.81 * 6.5 / 1000.0, 1e-12);
  // a 10 per mille rise costs g * 0.01; coasting at standstill does not roll back
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{}, 5.0, 10.0), -0.0981, 1e-12);
  EXPECT_EQ(Advance(Motion{10.0, 0.0}, NetAcceleration(NoResistance(), Control{}, 0.0, 10.0), 0.1).position_m, 10.0);
  // no traction at or above the maximum speed; traction and brake commands are clamped
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{5.0, 0.0, false}, p.max_speed_mps, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{5.0, 0.0, false}, 1.0, 0.0), 1.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{0.0, 9.0, false}, 1.0, 0.0), -1.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{1.0, 0.0, true}, 1.0, 0.0), -1.5, 1e-12);
}

TEST(SimDynamics, CurveSpeedInvertsTheStoppingDistance) {
  for (const double t : {0.0, 0.5, 2.0}) {
    for (const double v : {1.0, 5.56, 16.7, 27.8}) {
      const double d = StoppingDistance(v, 0.8, t);
      EXPECT_NEAR(CurveSpeed(d, 0.8, t), v, 1e-9);
    }
  }
  EXPECT_EQ(CurveSpeed(-1.0, 0.8, 1.0), 0.0);
  EXPECT_EQ(CurveSpeed(10.0, 0.0, 1.0), 0.0);
  // 20 km/h, 0.8 m/s^2, 1 s: 5.556 + 19.29 = 24.85 m
  EXPECT_NEAR(StoppingDistance(20.0 / 3.6, 0.8, 1.0), 20.0 / 3.6 + (20.0 / 3.6) * (20.0 / 3.6) / 1.6, 1e-12);
}

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

}  // namespace
}  // namespace railproof::sim
