// Unit tests of the two-counter speed-check design calculator (D3, digest §5;
// spec/design/br.md §6) with hand-computed values of the reference design
// (V_E 250 km/h, alpha 1 km/h/s, target 0.25 %, K = 1.5 per ASM-023: n_1F = 800,
// f_1 = f_M = 3840 Hz, T_s = 0.208333 s), and a simulation that drives the runtime
// br::TwoCounterSpeedCheck with synthetic TG pulse and oscillator trains under
// constant acceleration and checks that the brake decision flips within the computed
// total error around every check speed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "railproof/br/analysis/speedcheck_design.hpp"
#include "railproof/br/speed_check.hpp"
#include "railproof/generated/sc_params.hpp"

namespace railproof::br::analysis {
namespace {

constexpr double kEps = 1e-9;

// @verifies REQ-SC-004
TEST(SpeedCheckDesignRef, InputsComeFromTheParameters) {
  const SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  EXPECT_EQ(in.max_speed_kmh, 250.0);
  EXPECT_EQ(in.alpha_kmh_s, 1.0);
  EXPECT_DOUBLE_EQ(in.target_ratio, 0.0025);
  EXPECT_DOUBLE_EQ(in.reference_sampling_s, 0.312);
  EXPECT_EQ(in.check_speeds_kmh, (std::vector<double>{250, 210, 160, 110, 70, 30, 5}));
  EXPECT_EQ(in.tg_teeth, 90.0);
  EXPECT_EQ(in.wheel_diameter_mm, 860.0);
  EXPECT_DOUBLE_EQ(TimingFactor(in), 1.5);
}

// @verifies REQ-SC-004
TEST(SpeedCheckDesignRef, HandComputedErrorsOfTheReferenceDesign) {
  const SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  EXPECT_NEAR(OptimumN1F(in), 800.0, kEps);
  EXPECT_NEAR(AsymptoteN1F(in), 400.0, kEps);
  // f_M = 4 * 1.5 * 1 / 250 / 0.0025^2 = 3840 Hz
  EXPECT_NEAR(MinimumF1Hz(in), 3840.0, 1e-6);
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(in);
  EXPECT_EQ(d.n_1f, 800);
  EXPECT_EQ(d.f_1_hz, 3840.0);
  EXPECT_NEAR(d.sampling_s, 800.0 / 3840.0, kEps);  // 0.2083 s
  ASSERT_EQ(d.rows.size(), 7U);
  // 250 km/h: static 250/800 = 0.3125, dynamic 1 * 0.208333 * 1.5 = 0.3125, total 0.625
  const CheckSpeedRow& r250 = d.rows[0];
  EXPECT_NEAR(r250.static_kmh, 0.3125, kEps);
  EXPECT_NEAR(r250.dynamic_linear_kmh, 0.3125, kEps);
  EXPECT_NEAR(r250.total_kmh, 0.625, kEps);
  EXPECT_NEAR(r250.total_pct_of_check, 0.25, kEps);
  // exact D3 dynamic error: V_E' = 250.3125, dV_1 = 0.1041667, V_F = 250.4166667,
  // dV_1 + (sqrt(1 + 2 * 0.2083333 * 250.3125 / V_F^2) - 1) * V_F = 0.3123268
  EXPECT_NEAR(r250.dynamic_kmh, 0.31232682177, 1e-9);
  EXPECT_LE(r250.static_kmh + r250.dynamic_kmh, r250.total_kmh);
  // TG at 250 km/h: 69.444 m/s / (pi * 0.86 m) * 90 = 2313.30 Hz; n_2E = floor(481.94) = 481
  EXPECT_NEAR(r250.f_2e_hz, 2313.2985914, 1e-6);
  EXPECT_EQ(r250.n_2e, 481);
  EXPECT_TRUE(r250.meets_target);
  EXPECT_TRUE(r250.tg_ok);
  // 210 km/h: 210/800 + 0.3125 = 0.575 km/h; n_2E = floor(404.83) = 404
  EXPECT_NEAR(d.rows[1].total_kmh, 0.575, kEps);
  EXPECT_EQ(d.rows[1].n_2e, 404);
  // 5 km/h: 5/800 + 0.3125 = 0.31875 km/h (6.375 % of 5 km/h); n_2E = floor(9.64) = 9,
  // brake threshold 5 * 9 / 9.639 = 4.669 km/h
  const CheckSpeedRow& r5 = d.rows[6];
  EXPECT_NEAR(r5.total_kmh, 0.31875, kEps);
  EXPECT_NEAR(r5.total_pct_of_check, 6.375, 1e-9);
  EXPECT_NEAR(r5.dynamic_kmh, 0.30433339610, 1e-9);
  EXPECT_EQ(r5.n_2e, 9);
  EXPECT_NEAR(r5.threshold_kmh, 4.6690, 1e-3);
  const std::vector<std::int64_t> n2e{481, 404, 308, 212, 134, 57, 9};
  for (std::size_t i = 0; i < d.rows.size(); ++i) {
    const CheckSpeedRow& r = d.rows[i];
    EXPECT_EQ(r.n_2e, n2e[i]) << r.check_speed_kmh;
    EXPECT_LE(r.gate_s, d.sampling_s + kEps);           // counter 1 reaches at most n_1F
    EXPECT_LE(r.threshold_kmh, r.check_speed_kmh + kEps);  // rounding to the safe side
    EXPECT_LE(r.static_kmh + r.dynamic_kmh, r.total_kmh + kEps);
    EXPECT_TRUE(r.meets_target) << r.check_speed_kmh;   // <= 0.625 km/h (basis: V_E max)
    EXPECT_TRUE(r.tg_ok) << r.check_speed_kmh;
  }
  EXPECT_TRUE(d.MeetsTarget());
  EXPECT_TRUE(d.TgOk());
}

// @verifies REQ-SC-004
TEST(SpeedCheckDesignRef, PerCheckSpeedTargetCannotBeMetWithACommonSamplingTime) {
  SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  in.target_basis = TargetBasis::kCheckSpeed;
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(in);
  EXPECT_TRUE(d.rows[0].meets_target);  // 250: exactly 0.25 %
  for (std::size_t i = 1; i < d.rows.size(); ++i) {
    EXPECT_FALSE(d.rows[i].meets_target) << d.rows[i].check_speed_kmh;
  }
  EXPECT_FALSE(d.MeetsTarget());
}

// @verifies REQ-SC-004
TEST(SpeedCheckDesignRef, D3SamplingTimeConflictsWithTheOptimum) {
  const SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  // n_1F = 800 at T_s = 0.312 s: 0.3125 + 1.5 * 0.312 = 0.7805 km/h = 0.312 % > 0.25 %
  const double f = 800.0 / 0.312;
  EXPECT_NEAR(TotalErrorKmh(in, 250.0, 800.0, f), 0.7805, kEps);
  EXPECT_FALSE(MakeSpeedCheckDesign(in, 800, f).MeetsTarget());
  // smallest n_1F meeting the target at 0.312 s: 250 / (0.625 - 0.468) = 1592.4 -> 1593,
  // f_1 = 1593 / 0.312 = 5105.8 -> 5106 Hz (above f_M: off the optimum)
  const SpeedCheckDesign fixed = FixedSamplingSpeedCheckDesign(in, 0.312);
  EXPECT_EQ(fixed.n_1f, 1593);
  EXPECT_EQ(fixed.f_1_hz, 5106.0);
  EXPECT_TRUE(fixed.MeetsTarget());
  EXPECT_GT(fixed.f_1_hz, MinimumF1Hz(in));
  // no design at all once alpha T_s K reaches the target: T_s >= 0.625 / 1.5 = 0.4167 s
  EXPECT_THROW((void)FixedSamplingSpeedCheckDesign(in, 0.42), std::invalid_argument);
}

// ---- the design curve -----------------------------------------------------------------------

// @verifies REQ-SC-004
TEST(SpeedCheckDesignCurve, OptimumGivesTwiceTheStaticErrorIndependentOfAlpha) {
  for (const double alpha : {0.25, 1.0, 3.5}) {
    for (const double r : {0.001, 0.0025, 0.01}) {
      SpeedCheckInputs in = ReferenceSpeedCheckInputs();
      in.alpha_kmh_s = alpha;
      in.target_ratio = r;
      const double n = OptimumN1F(in);
      const double f = MinimumF1Hz(in);
      EXPECT_NEAR(DesignCurveF1Hz(in, n), f, 1e-9 * f);
      const double total = TotalErrorKmh(in, 250.0, n, f);
      EXPECT_NEAR(total, 2.0 * 250.0 / n, 1e-9) << alpha << " " << r;
      EXPECT_NEAR(total, r * 250.0, 1e-9);
      // the static and the dynamic part are equal there
      EXPECT_NEAR(StaticErrorKmh(250.0, n), alpha * SamplingTimeS(n, f) * 1.5, 1e-9);
    }
  }
}

// @verifies REQ-SC-004
TEST(SpeedCheckDesignCurve, MinimumAtTwoOverRAndAsymptoteAtOneOverR) {
  const SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  const double n_m = OptimumN1F(in);
  const double f_m = DesignCurveF1Hz(in, n_m);
  for (const double dn : {0.01, 1.0, 10.0, 100.0}) {
    EXPECT_GT(DesignCurveF1Hz(in, n_m - dn), f_m) << dn;
    EXPECT_GT(DesignCurveF1Hz(in, n_m + dn), f_m) << dn;
  }
  // every point on the curve meets the target exactly
  for (const double n : {450.0, 800.0, 2000.0}) {
    EXPECT_NEAR(TotalErrorKmh(in, 250.0, n, DesignCurveF1Hz(in, n)), 0.625, 1e-9);
  }
  // asymptote: no design at or left of n_1F = 1/r = 400, f_1 -> infinity from the right
  EXPECT_EQ(DesignCurveF1Hz(in, 400.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(DesignCurveF1Hz(in, 300.0), std::numeric_limits<double>::infinity());
  EXPECT_GT(DesignCurveF1Hz(in, 400.01), 1e7);
  double prev = std::numeric_limits<double>::infinity();
  for (double n = 401.0; n <= n_m; n += 1.0) {  // strictly decreasing down to the minimum
    const double f = DesignCurveF1Hz(in, n);
    EXPECT_LT(f, prev);
    prev = f;
  }
  // far right: grows like K alpha n / (r V_E) (T_s -> r V_E / (alpha K))
  const double n_big = 1e7;
  EXPECT_NEAR(DesignCurveF1Hz(in, n_big) / n_big, 1.5 / (0.0025 * 250.0), 1e-3);
  const auto curve = DesignCurve(in, 4000.0, 50);
  ASSERT_EQ(curve.size(), 50U);
  EXPECT_GT(curve.front().first, 400.0);
  EXPECT_NEAR(curve.back().first, 4000.0, 1e-6);
  for (const auto& [n, f] : curve) {
    EXPECT_GE(f, f_m * (1 - 1e-12));
  }
}

// ---- TG constraint (REQ-SC-006) -------------------------------------------------------------

// @verifies REQ-SC-006
TEST(SpeedCheckDesignTg, DetectsATgTooSlowForTheSamplingTime) {
  const SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  EXPECT_NEAR(TgFrequencyHz(in, 5.0), 5.0 / 3.6 * 1000.0 / (std::numbers::pi * 860.0) * 90.0,
              1e-9);
  // T_s = 10 / 10000 Hz = 1 ms: at 5 km/h the TG gives 0.046 pulses per gate, n_2E = 1
  const SpeedCheckDesign d = MakeSpeedCheckDesign(in, 10, 10000.0);
  const CheckSpeedRow& r5 = d.rows[6];
  EXPECT_EQ(r5.n_2e, 1);
  EXPECT_NEAR(r5.tg_limit_hz, r5.f_2e_hz * 10.0, 1e-9);
  EXPECT_FALSE(r5.tg_ok);
  EXPECT_TRUE(d.rows[0].tg_ok);  // 250 km/h: 2.3 pulses per gate, n_2E = 2
  EXPECT_FALSE(d.TgOk());
  // the constraint is f_1 <= f_2E n_1F / n_2E: check it directly on the reference
  const SpeedCheckDesign ref = OptimumSpeedCheckDesign(in);
  for (const CheckSpeedRow& r : ref.rows) {
    EXPECT_LE(ref.f_1_hz, r.f_2e_hz * static_cast<double>(ref.n_1f) / static_cast<double>(r.n_2e));
  }
}

// @verifies REQ-SC-004
TEST(SpeedCheckDesignInputs, RejectsInvalidInputs) {
  SpeedCheckInputs in = ReferenceSpeedCheckInputs();
  in.check_speeds_kmh.push_back(300.0);  // above V_E max
  EXPECT_THROW((void)OptimumSpeedCheckDesign(in), std::invalid_argument);
  in = ReferenceSpeedCheckInputs();
  in.target_ratio = 0.0;
  EXPECT_THROW((void)OptimumSpeedCheckDesign(in), std::invalid_argument);
  in = ReferenceSpeedCheckInputs();
  EXPECT_THROW((void)MakeSpeedCheckDesign(in, 0, 3840.0), std::invalid_argument);
  EXPECT_THROW((void)MakeSpeedCheckDesign(in, 800, 0.0), std::invalid_argument);
}

// ---- error bound and allowance (REQ-SC-005) -------------------------------------------------

// @verifies REQ-SC-005
TEST(SpeedCheckDesignBound, SpeedErrorBoundOfTheReferenceDesign) {
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  // dynamic part: 277.78 mm/s^2 * 0.208333 s * 1.5 = 86.806 mm/s
  EXPECT_EQ(SpeedErrorBoundMmS(d, 0), 87);
  // 250 km/h = 69444 mm/s: 69444 / 800 + 86.806 = 173.61 -> 174
  EXPECT_EQ(SpeedErrorBoundMmS(d, 69444), 174);
  EXPECT_EQ(KmhToMmSCeil(250.0), 69445);
  EXPECT_EQ(KmhToMmSCeil(90.0), 25000);
  // 100 km/h = 27778 mm/s: 34.72 + 86.81 = 121.53 -> 122
  EXPECT_EQ(SpeedErrorBoundMmS(d, 27778), 122);
  // consistent with the design's total error at the check speed
  EXPECT_GE(static_cast<double>(SpeedErrorBoundMmS(d, 69444)),
            d.rows[0].total_kmh * 2500.0 / 9.0 - 1.0);
  EXPECT_THROW((void)SpeedErrorBoundMmS(d, -1), std::invalid_argument);
}

// @verifies REQ-SC-005
TEST(SpeedCheckDesignBound, AllowanceCoversReportsTheWorstShortfall) {
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  // the train types' allowance (2500 ppm + 174 mm/s) up to 110 km/h + 5 km/h overspeed
  const AllowanceCheck ok = AllowanceCovers(d, 2500, 174, KmhToMmSCeil(115.0));
  EXPECT_TRUE(ok.Covered());
  EXPECT_LT(ok.worst_shortfall_mm_s, 0);
  // no proportional part: the static error v/800 is not covered at high speed
  const AllowanceCheck abs_only = AllowanceCovers(d, 0, 87, 69444);
  EXPECT_FALSE(abs_only.Covered());
  // worst where the bound first reaches its top value 174 (68956 / 800 + 86.806 > 173)
  EXPECT_EQ(abs_only.worst_shortfall_mm_s, 174 - 87);
  EXPECT_EQ(abs_only.at_speed_mm_s, 68956);
  EXPECT_EQ(SpeedErrorBoundMmS(d, 68955), 173);
  // allowance below the dynamic part: short already at standstill (bound 87 at v = 0)
  const AllowanceCheck low = AllowanceCovers(d, 2500, 80, 0);
  EXPECT_EQ(low.worst_shortfall_mm_s, 7);
  EXPECT_EQ(low.at_speed_mm_s, 0);
  // exactly enough: abs = 87, ppm = 1250 + rounding slack
  EXPECT_TRUE(AllowanceCovers(d, 1300, 88, 69444).Covered());
  EXPECT_THROW((void)AllowanceCovers(d, -1, 0, 10), std::invalid_argument);
}

// ---- runtime configuration and simulation ---------------------------------------------------

// @verifies REQ-SC-002
TEST(SpeedCheckDesignRuntime, ReferenceDesignConfiguresTheRuntimeCheck) {
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  std::vector<br::CheckSpeedEntry> table;
  const auto config = ToRuntimeConfig(d, params::sc::gate_timeout_ms, 2, table);
  EXPECT_EQ(config.f_1_hz, 3840);
  EXPECT_EQ(config.n_1f, 800);
  ASSERT_EQ(config.table.size(), 7U);
  EXPECT_EQ(config.table[0].check_speed_kmh, 250);
  EXPECT_EQ(config.table[0].n_2e, 481);
  EXPECT_EQ(config.table[6].check_speed_kmh, 5);
  EXPECT_EQ(config.table[6].n_2e, 9);
  const auto created = br::TwoCounterSpeedCheck::Create(config, 0);
  EXPECT_EQ(created.error, br::SpeedCheckConfigError::kNone);
}

struct FlipResult {
  bool found = false;             // the decision flipped
  bool monotone = true;           // every decision before the flip was the opposite one
  double v_kmh = 0.0;             // true speed at the flipping gate's close
  int decisions = 0;
};

// Drives the runtime check at check speed `check_kmh` with a train starting at v0_kmh and
// accelerating at a_kmh_s (negative: braking), for up to t_end_s. TG pulse k at distance
// (k + pulse_phase) * tooth pitch; oscillator tick j at (j + tick_phase) / f_1. Returns the
// first gate decision equal to `want_brake` (after only opposite decisions).
FlipResult Drive(const SpeedCheckDesign& d, double check_kmh, double v0_kmh, double a_kmh_s,
                 double tick_phase, double pulse_phase, bool want_brake, double t_end_s) {
  std::vector<br::CheckSpeedEntry> table;
  const auto config = ToRuntimeConfig(d, params::sc::gate_timeout_ms, 2, table);
  auto created = br::TwoCounterSpeedCheck::Create(config, 0);
  EXPECT_EQ(created.error, br::SpeedCheckConfigError::kNone);
  auto& check = *created.check;
  EXPECT_EQ(check.SelectCheckSpeed(std::llround(check_kmh), 0), br::SelectVerdict::kSelected);

  const double pitch_m = std::numbers::pi * d.inputs.wheel_diameter_mm / 1000.0 /
                         d.inputs.tg_teeth;
  const double v0 = v0_kmh / 3.6;
  const double a = a_kmh_s / 3.6;
  const auto pulse_time = [&](std::int64_t k) {
    const double s = (static_cast<double>(k) + pulse_phase) * pitch_m;
    const double disc = v0 * v0 + 2.0 * a * s;
    if (disc < 0.0) {
      return std::numeric_limits<double>::infinity();  // the train stops first
    }
    return 2.0 * s / (std::sqrt(disc) + v0);  // (sqrt(disc) - v0) / a without cancellation
  };
  const double f_1 = static_cast<double>(config.f_1_hz);
  FlipResult out;
  std::int64_t k = 0;
  std::int64_t j = 0;
  double tp = pulse_time(k);
  double tt = tick_phase / f_1;
  while (std::min(tp, tt) < t_end_s) {
    if (tt <= tp) {
      check.OnOscillatorTick(static_cast<std::int64_t>(std::floor(tt * 1000.0)));
      ++j;
      tt = (static_cast<double>(j) + tick_phase) / f_1;
      continue;
    }
    const br::GateResult g =
        check.OnTgPulse(static_cast<std::int64_t>(std::floor(tp * 1000.0)));
    if (g.closed) {
      ++out.decisions;
      if (g.brake == want_brake) {
        out.found = true;
        out.v_kmh = v0_kmh + a_kmh_s * tp;
        return out;
      }
    }
    ++k;
    tp = pulse_time(k);
  }
  return out;
}

// @verifies REQ-SC-001 REQ-SC-002 REQ-SC-004
TEST(SpeedCheckDesignRuntime, SimulatedBrakeDecisionFlipsWithinTheTotalError) {
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  const double alpha = d.inputs.alpha_kmh_s;
  const double phases[][2] = {{0.0, 0.0}, {0.37, 0.5}, {0.81, 0.23}};
  for (const CheckSpeedRow& r : d.rows) {
    const double v = r.check_speed_kmh;
    for (const auto& ph : phases) {
      // accelerating through the check speed: the first brake decision comes at a true speed
      // no higher than V_E + dV (safety) and no lower than V_th - dV (availability)
      const FlipResult up = Drive(d, v, v - 2.5, alpha, ph[0], ph[1], true, 5.0);
      ASSERT_TRUE(up.found) << v;
      EXPECT_GE(up.decisions, 2) << v;  // released before
      EXPECT_LE(up.v_kmh, v + r.total_kmh) << v;
      EXPECT_GE(up.v_kmh, r.threshold_kmh - r.total_kmh) << v;
      // braking through it: the first release comes below the threshold
      const FlipResult down = Drive(d, v, v + 2.5, -alpha, ph[0], ph[1], false, 5.0);
      ASSERT_TRUE(down.found) << v;
      EXPECT_GE(down.decisions, 2) << v;
      EXPECT_LE(down.v_kmh, r.threshold_kmh) << v;
      EXPECT_GE(down.v_kmh, r.threshold_kmh - r.total_kmh) << v;
    }
  }
}

// @verifies REQ-SC-001
TEST(SpeedCheckDesignRuntime, ConstantSpeedDecisionsMatchTheThreshold) {
  const SpeedCheckDesign d = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  for (const CheckSpeedRow& r : d.rows) {
    const double v = r.check_speed_kmh;
    // at the check speed (>= threshold) every gate brakes; 1/n_1F + a margin below the
    // threshold every gate releases. A tiny acceleration stands in for constant speed.
    const FlipResult at = Drive(d, v, v, 1e-9, 0.5, 0.5, false, 2.0);
    EXPECT_FALSE(at.found) << v;
    EXPECT_GE(at.decisions, 3) << v;
    const double below = r.threshold_kmh * (1.0 - 2.0 / static_cast<double>(d.n_1f));
    const FlipResult slow = Drive(d, v, below, 1e-9, 0.5, 0.5, true, 2.0);
    EXPECT_FALSE(slow.found) << v;
    EXPECT_GE(slow.decisions, 3) << v;
  }
}

}  // namespace
}  // namespace railproof::br::analysis
