// Unit tests of the offline train-motion model (railproof/offline/dynamics.hpp): forces,
// constant-acceleration motion, braking curves (hand-checked cases) and the speed limits
// acting on a train.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::offline {
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

TEST(Dynamics, AccelerationFromStandstillMatchesHandCalculation) {
  // a = 1 m/s^2 for 10 s: v = 10 m/s, s = a t^2 / 2 = 50 m (exact integration per step)
  const TrainPerformance p = NoResistance();
  Motion m{0.0, 0.0};
  for (int k = 0; k < 100; ++k) {
    const double a = NetAcceleration(p, Control{1.0, 0.0, false}, m.speed, 0.0);
    m = Advance(m, a, 0.1);
  }
  EXPECT_NEAR(m.speed, 10.0, 1e-9);
  EXPECT_NEAR(m.position, 50.0, 1e-9);
}

TEST(Dynamics, ServiceAndEmergencyBrakingDistancesMatchHandCalculation) {
  // from 20 m/s: service 1 m/s^2 stops in v^2 / 2b = 200 m after 20 s; emergency 1.5 m/s^2
  // in 133.33 m; the train stops and does not roll back
  const TrainPerformance p = NoResistance();
  for (const bool emergency : {false, true}) {
    Motion m{1000.0, 20.0};
    int steps = 0;
    while (m.speed > 0.0 && steps < 1000) {
      const double a = NetAcceleration(p, Control{0.0, 1.0, emergency}, m.speed, 0.0);
      m = Advance(m, a, 0.1);
      ++steps;
    }
    const double b = emergency ? 1.5 : 1.0;
    EXPECT_NEAR(m.position - 1000.0, 400.0 / (2.0 * b), 1e-9);
    EXPECT_NEAR(steps * 0.1, 20.0 / b, 0.1 + 1e-9);
    EXPECT_NEAR(StoppingDistance(20.0, b, 0.0), 400.0 / (2.0 * b), 1e-12);
    const Motion still = Advance(m, NetAcceleration(p, Control{0.0, 1.0, emergency}, 0.0, 0.0), 0.1);
    EXPECT_EQ(still.position, m.position);
    EXPECT_EQ(still.speed, 0.0);
  }
}

TEST(Dynamics, ResistanceGradientAndLimits) {
  TrainPerformance p = NoResistance();
  p.resistance = Resistance{1.5, 0.02, 0.0003};
  // r(100 km/h) = 1.5 + 2 + 3 = 6.5 N/kN -> 9.81 * 6.5 / 1000 m/s^2
  EXPECT_NEAR(ResistanceDecel(p.resistance, 100.0 / 3.6), 9.81 * 6.5 / 1000.0, 1e-12);
  // a 10 per mille rise costs g * 0.01; coasting at standstill does not roll back
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{}, 5.0, 10.0), -0.0981, 1e-12);
  EXPECT_EQ(Advance(Motion{10.0, 0.0}, NetAcceleration(NoResistance(), Control{}, 0.0, 10.0), 0.1).position, 10.0);
  // no traction at or above the maximum speed; traction and brake commands are clamped
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{5.0, 0.0, false}, p.max_speed_mps, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{5.0, 0.0, false}, 1.0, 0.0), 1.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{0.0, 9.0, false}, 1.0, 0.0), -1.0, 1e-12);
  EXPECT_NEAR(NetAcceleration(NoResistance(), Control{1.0, 0.0, true}, 1.0, 0.0), -1.5, 1e-12);
}

// The handbook form of an EMU consist (ASM-032) for D2's ten cars (motor cars 170 t, trailers
// 125 t): a0 = 378/295, a1 = 4.549/295, a2 = 0.0982/295, about 4.65 N/kN at 80 km/h.
TEST(Dynamics, ConsistResistanceByHand) {
  const Resistance r = ConsistResistance(Consist{10, 170.0, 125.0});
  EXPECT_NEAR(r.a0, 378.0 / 295.0, 1e-12);
  EXPECT_NEAR(r.a1, 4.549 / 295.0, 1e-12);
  EXPECT_NEAR(r.a2, 0.0982 / 295.0, 1e-12);
  EXPECT_NEAR(ResistanceDecel(r, 80.0 / 3.6), 9.81 * 4.6454 / 1000.0, 1e-4);
}

// Curve resistance 800 / R (ASM-034): 2.67 N/kN in a 300 m curve, nothing on straight track.
TEST(Dynamics, CurveResistanceByHand) {
  EXPECT_NEAR(CurveResistancePermille(300.0), 800.0 / 300.0, 1e-12);
  EXPECT_NEAR(CurveResistancePermille(1000.0), 0.8, 1e-12);
  EXPECT_DOUBLE_EQ(CurveResistancePermille(0.0), 0.0);
}

// The mean gradient and curve resistance under a 100 m train, by hand: gradients +10 per
// mille on [0, 500 m) and -5 on [500, 1000 m), a 400 m curve on [600, 700 m).
TEST(Dynamics, MeanGradientAndCurveResistanceUnderTheTrain) {
  RunningLine rl;
  rl.length_mm = 1'000'000;
  rl.gradients = {Gradient{{0, 500'000}, 100}, Gradient{{500'000, 1'000'000}, -50}};
  rl.curves = {Curve{{600'000, 700'000}, 400}};
  EXPECT_DOUBLE_EQ(rl.MeanGradientPermille(300'000.0, 400'000.0), 10.0);
  EXPECT_DOUBLE_EQ(rl.MeanGradientPermille(450'000.0, 550'000.0), 2.5);  // half on each
  // beyond the ends the first and last gradients continue
  EXPECT_DOUBLE_EQ(rl.MeanGradientPermille(-50'000.0, 50'000.0), 10.0);
  EXPECT_DOUBLE_EQ(rl.MeanGradientPermille(950'000.0, 1'050'000.0), -5.0);
  EXPECT_DOUBLE_EQ(rl.MeanGradientPermille(500'000.0, 500'000.0), -5.0);  // a point
  EXPECT_DOUBLE_EQ(rl.MeanCurveResistancePermille(500'000.0, 600'000.0), 0.0);
  EXPECT_DOUBLE_EQ(rl.MeanCurveResistancePermille(600'000.0, 700'000.0), 2.0);
  EXPECT_DOUBLE_EQ(rl.MeanCurveResistancePermille(675'000.0, 775'000.0), 0.5);  // a quarter in it
  EXPECT_DOUBLE_EQ(rl.MeanCurveResistancePermille(650'000.0, 650'000.0), 2.0);
}

// Traction is constant up to the constant-power speed and falls as 1/v above it; without that
// speed it stays constant.
TEST(Dynamics, MaxTractionFallsAboveTheConstantPowerSpeed) {
  TrainPerformance p;
  p.accel_mps2 = 1.0;
  EXPECT_DOUBLE_EQ(MaxTraction(p, 30.0), 1.0);
  p.constant_power_from_mps = 10.0;
  EXPECT_DOUBLE_EQ(MaxTraction(p, 5.0), 1.0);
  EXPECT_DOUBLE_EQ(MaxTraction(p, 10.0), 1.0);
  EXPECT_DOUBLE_EQ(MaxTraction(p, 20.0), 0.5);
  p.max_speed_mps = 40.0;
  Control full;
  full.traction_mps2 = 1.0;
  EXPECT_NEAR(NetAcceleration(p, full, 20.0, 0.0), 0.5 - ResistanceDecel(p.resistance, 20.0), 1e-12)
      << "the commanded traction is capped by the constant-power curve";
}

TEST(Dynamics, CurveSpeedInvertsTheStoppingDistance) {
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

TEST(Dynamics, GradeDecelInTheUnitOfGravity) {
  EXPECT_DOUBLE_EQ(GradeDecel(10.0), 0.0981);         // m/s^2, the simulation's gravity
  EXPECT_DOUBLE_EQ(GradeDecel(-3.5, 9807.0), -34.3245);  // mm/s^2, falling: accelerates
  EXPECT_DOUBLE_EQ(GradeDecel(0.0, 9807.0), 0.0);
}

TEST(Dynamics, SpeedAfterAndTimeOverADistance) {
  // from 10 m/s over 75 m at 1 m/s^2: v^2 = 100 + 150, v = sqrt(250); t = 2 d / (v0 + v1)
  const double v = SpeedAfter(10.0, 1.0, 75.0);
  EXPECT_DOUBLE_EQ(v, std::sqrt(250.0));
  EXPECT_NEAR(TimeOver(75.0, 10.0, v), (v - 10.0) / 1.0, 1e-12);
  // braking: stops before the end of the distance
  EXPECT_EQ(SpeedAfter(10.0, -1.0, 60.0), 0.0);
  EXPECT_DOUBLE_EQ(SpeedAfter(10.0, -1.0, 50.0), 0.0);
  EXPECT_DOUBLE_EQ(SpeedAfter(10.0, -1.0, 32.0), 6.0);
  // the same piece read backwards: accelerating from the slower end
  EXPECT_DOUBLE_EQ(SpeedAfter(6.0, 1.0, 32.0), 10.0);
}

TEST(Dynamics, TimeToCoverInvertsAdvance) {
  for (const double v : {0.0, 3.0, 20.0}) {
    for (const double a : {-1.0, 0.0, 0.5}) {
      for (const double t : {0.5, 2.0}) {
        const Motion m = Advance(Motion{0.0, v}, a, t);
        if (m.speed > 0.0 && m.position > 0.0) {
          EXPECT_NEAR(TimeToCover(v, a, m.position), t, 1e-9) << v << " " << a << " " << t;
        }
      }
    }
  }
  EXPECT_EQ(TimeToCover(5.0, 1.0, 0.0), 0.0);
  EXPECT_EQ(TimeToCover(10.0, -1.0, 60.0), std::numeric_limits<double>::infinity());  // stops at 50 m
  EXPECT_EQ(TimeToCover(0.0, 0.0, 1.0), std::numeric_limits<double>::infinity());      // stands
  EXPECT_NEAR(TimeToCover(10.0, -1.0, 50.0), 10.0, 1e-9);                              // stops there
}

TEST(Dynamics, SpeedLimitsActOnTheWholeTrain) {
  RunningLine rl;
  rl.speed_limits = {{{0, 1'000'000}, 100}, {{1'000'000, 2'000'000}, 60}, {{2'000'000, 3'000'000}, 80}};
  const auto acting = [&](double rear, double front, double mm_per_unit = 1.0) {
    std::vector<std::size_t> out;
    rl.ForEachLimitActing(rear, front, [&](std::size_t i) { out.push_back(i); }, mm_per_unit);
    return out;
  };
  EXPECT_EQ(acting(500'000.0, 900'000.0), (std::vector<std::size_t>{0}));
  // a limit acts from its begin reaching the front ...
  EXPECT_EQ(acting(800'000.0, 1'000'000.0), (std::vector<std::size_t>{0, 1}));
  // ... until its end has left the rear
  EXPECT_EQ(acting(1'999'999.0, 2'100'000.0), (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(acting(2'000'000.0, 2'100'000.0), (std::vector<std::size_t>{2}));
  // in metres
  EXPECT_EQ(acting(999.0, 2000.0, 1000.0), (std::vector<std::size_t>{0, 1, 2}));
}

}  // namespace
}  // namespace railproof::offline
