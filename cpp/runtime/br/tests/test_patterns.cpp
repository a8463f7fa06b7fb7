// Unit tests of the braking patterns (spec/design/br.md §1-§3) with hand-computed
// values (closed forms of the real braking curve, and integer values checked by an
// independent brute force over every speed), a straightforward double-precision reference
// implementation of the design note (no pieces, no suffix minima, no sparse tables) for the
// randomised comparison, the profile validation (one test per reason), the runtime rules
// (no allocation after Create, determinism) and monotonicity.
//
// Kills the seeded faults FAULT_BR_NO_FREE_RUNNING, FAULT_BR_GRADIENT_FRONT_ONLY,
// FAULT_BR_RESTRICTION_FRONT_RELEASE, FAULT_BR_NO_SPEED_ALLOWANCE (ctest unit_fault_<F>: these tests against the schemata variant with the fault selected).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "railproof/testing/alloc_counter.hpp"
#include "railproof/br/patterns.hpp"
#include "railproof/br/supervisor.hpp"
#include "railproof/generated/br_params.hpp"

namespace railproof::br {
namespace {

// spec/trains/*.yaml pattern values (max of the ranges; 5 km/h = 1388.9 mm/s -> 1389).
TrainData Emu3() {
  return TrainData{60'000, 920, 1'000, 900, 1'500, 2'500, 1'389, 2'500, 174};
}
TrainData Dmu2() {
  return TrainData{40'000, 600, 900, 800, 2'000, 3'000, 1'389, 2'500, 174};
}
TrainData Emu10() {
  return TrainData{200'000, 830, 1'050, 972, 1'500, 2'000, 1'389, 2'500, 174};
}

PatternCalculator Make(const TrainData& t = Emu3(), std::size_t capacity = kDefaultProfileCapacity) {
  auto created = PatternCalculator::Create(t, DefaultSupervisionParams(), capacity);
  EXPECT_EQ(created.error, CreateError::kNone) << ToString(created.error);
  return std::move(*created.calculator);
}

PatternCalculator MakeWith(const std::vector<GradientSegment>& g, const std::vector<RestrictionSegment>& r,
                           const TrainData& t = Emu3()) {
  PatternCalculator c = Make(t);
  const ProfileResult res = c.SetProfile(g, r);
  EXPECT_EQ(res.verdict, ProfileVerdict::kAccept) << ToString(res.verdict) << " entry " << res.entry;
  return c;
}

// Real solution v of (v + aT)^2 = V^2 + 2 b (D - v T - a T^2 / 2) (run-up at a for T, then
// braking at b over the remaining distance to the target at V): design note §3 with real
// arithmetic and constant a, b. Units mm, mm/s, mm/s^2, ms.
double ClosedForm(double a, double b, double t_ms, double v_target, double d_mm) {
  const double t = t_ms / 1000.0;
  return -(a + b) * t + std::sqrt(b * t * t * (a + b) + v_target * v_target + 2.0 * b * d_mm);
}

// ---- double-precision reference of design note §3 -------------------------------------
struct Reference {
  TrainData t;
  SupervisionParams s;
  std::vector<GradientSegment> g;
  std::vector<RestrictionSegment> r;
  std::vector<std::int64_t> bps;  // positions where G_eff may change

  Reference(const TrainData& train, std::vector<GradientSegment> grads, std::vector<RestrictionSegment> restr)
      : t(train), s(DefaultSupervisionParams()), g(std::move(grads)), r(std::move(restr)) {
    for (const auto& seg : g) {
      for (std::int64_t x : {seg.begin_mm, seg.end_mm, seg.begin_mm + t.length_mm, seg.end_mm + t.length_mm}) {
        bps.push_back(x);
      }
    }
    std::sort(bps.begin(), bps.end());
    bps.erase(std::unique(bps.begin(), bps.end()), bps.end());
    Prepare();
  }

  // lowest gradient over the train (y - length, y] (uncovered parts level) minus the error
  [[nodiscard]] std::int64_t Geff(std::int64_t y) const {
    const std::int64_t lo = y - t.length_mm;
    std::int64_t worst = std::numeric_limits<std::int64_t>::max();
    std::int64_t cover = lo;
    bool gap = false;
    for (const auto& seg : g) {
      if (seg.end_mm <= lo || seg.begin_mm > y) {
        continue;
      }
      if (seg.begin_mm > cover) {
        gap = true;
      }
      cover = std::max(cover, seg.end_mm);
      worst = std::min(worst, seg.permille_x10);
    }
    if (cover <= y) {
      gap = true;
    }
    if (gap) {
      worst = std::min<std::int64_t>(worst, 0);
    }
    return worst - s.gradient_error_x10;
  }
  [[nodiscard]] double Grav(std::int64_t g_x10) const {
    return static_cast<double>(g_x10) * static_cast<double>(s.gravity_mm_s2) / 10000.0;
  }
  [[nodiscard]] double Beta(Pattern p) const {
    return static_cast<double>(p == Pattern::kEmergency ? t.beta_e_mm_s2 : t.beta_n7_mm_s2);
  }
  [[nodiscard]] double TMs(Pattern p) const {
    return static_cast<double>(s.cycle_ms + s.reaction_ms +
                               (p == Pattern::kEmergency ? t.emergency_free_running_ms
                                                         : t.service_free_running_ms));
  }
  // B(y) = integral of b from kOrigin (real arithmetic, G_eff constant between breakpoints,
  // evaluated by brute force once per breakpoint; prefix sums per pattern)
  static constexpr std::int64_t kOrigin = -1'000'000'000;
  std::vector<std::int64_t> g_at_bp;          // G_eff on [bps[k], bps[k+1])
  std::vector<long double> b_prefix[2];       // B(bps[k]) per pattern
  void Prepare() {
    g_at_bp.clear();
    for (std::int64_t bp : bps) {
      g_at_bp.push_back(Geff(bp));
    }
    for (Pattern p : {Pattern::kEmergency, Pattern::kService}) {
      auto& pre = b_prefix[p == Pattern::kEmergency ? 0 : 1];
      pre.clear();
      long double sum = 0;
      double from = static_cast<double>(kOrigin);
      std::int64_t g_here = Geff(kOrigin);
      for (std::size_t k = 0; k < bps.size(); ++k) {
        const auto x = static_cast<double>(bps[k]);
        sum += static_cast<long double>(Beta(p) + Grav(g_here)) * static_cast<long double>(x - from);
        pre.push_back(sum);
        from = x;
        g_here = g_at_bp[k];
      }
    }
  }
  [[nodiscard]] long double B(Pattern p, double y) const {
    const auto& pre = b_prefix[p == Pattern::kEmergency ? 0 : 1];
    // last breakpoint strictly below y
    const auto it = std::lower_bound(bps.begin(), bps.end(), y,
                                     [](std::int64_t bp, double v) { return static_cast<double>(bp) < v; });
    if (it == bps.begin()) {
      return static_cast<long double>(Beta(p) + Grav(Geff(kOrigin))) *
             static_cast<long double>(y - static_cast<double>(kOrigin));
    }
    const auto k = static_cast<std::size_t>(it - bps.begin()) - 1;
    return pre[k] + static_cast<long double>(Beta(p) + Grav(g_at_bp[k])) *
                        static_cast<long double>(y - static_cast<double>(bps[k]));
  }
  // run-up acceleration: steepest falling G_eff over fronts [y - env, y + d_T(max_speed)]
  // (env = front + rear error; the window length is the design's integer definition)
  [[nodiscard]] double A(Pattern p, std::int64_t y, std::int64_t env = 0) const {
    std::int64_t gmin_all = 0;
    for (const auto& seg : g) {
      gmin_all = std::min(gmin_all, seg.permille_x10);
    }
    gmin_all -= s.gradient_error_x10;
    const std::int64_t grav_all = static_cast<std::int64_t>(
        std::floor(static_cast<double>(gmin_all * s.gravity_mm_s2) / 10000.0));
    const std::int64_t a_bound = t.accel_max_mm_s2 + std::max<std::int64_t>(0, -grav_all);
    const auto t_ms = static_cast<std::int64_t>(TMs(p));
    const std::int64_t num = 2000 * s.max_speed_mm_s * t_ms + a_bound * t_ms * t_ms;
    const std::int64_t window = (num + 1'999'999) / 2'000'000;
    std::int64_t gmin = Geff(y - env);
    for (std::size_t k = 0; k < bps.size(); ++k) {
      if (bps[k] > y - env && bps[k] <= y + window) {
        gmin = std::min(gmin, g_at_bp[k]);
      }
    }
    return static_cast<double>(t.accel_max_mm_s2) + std::max(0.0, -Grav(gmin));
  }
  // Largest gap the safe-side roundings can open between the real and the integer pattern
  // (design note §1): the floored braking capability (< 1 mm/s^2 on b >= b_min changes W by
  // a factor > 1 - 1/b_min, so v + A by at most (v + A) / (2 b_min)), the ceiled run-up
  // (< 1 mm/s on A, < 1 mm on d, worth < 1 mm/s), the floored gravity term of a (< T/1000 mm/s
  // on A, < T^2/2e6 mm on d) and the integer search (< 1 mm/s).
  [[nodiscard]] double GapBound(Pattern p, double real) const {
    std::int64_t gmin_all = 0;
    for (const auto& seg : g) {
      gmin_all = std::min(gmin_all, seg.permille_x10);
    }
    gmin_all -= s.gradient_error_x10;
    const double b_min = Beta(p) + Grav(gmin_all) - 1.0;
    const double tt = TMs(p) / 1000.0;
    const double a_max = static_cast<double>(t.accel_max_mm_s2) - Grav(gmin_all) + 1.0;
    return 4.0 + 2.0 * tt + (real + a_max * tt) / (2.0 * b_min);
  }
  // real pattern speed (bisection to 1e-7 mm/s on the same monotone predicate)
  [[nodiscard]] double Speed(Pattern p, std::int64_t y, std::int64_t limit, std::int64_t ext) const {
    const double tt = TMs(p) / 1000.0;
    const double a = A(p, y, std::max<std::int64_t>(0, ext - t.length_mm));
    const double stop = static_cast<double>(p == Pattern::kEmergency ? limit : limit - s.service_offset_mm);
    const double os = p == Pattern::kEmergency ? static_cast<double>(t.overspeed_mm_s) : 0.0;
    const long double b_stop = B(p, stop);
    const double yd = static_cast<double>(y);
    auto passes = [&](double v) {
      const double z = yd + v * tt + a * tt * tt / 2.0;
      if (z >= stop) {
        return false;
      }
      const long double bz = B(p, z);
      long double w = 2 * (b_stop - bz);
      for (const auto& rs : r) {
        const double vt = static_cast<double>(rs.limit_mm_s) + os;
        if (static_cast<double>(rs.begin_mm) > z) {
          w = std::min(w, static_cast<long double>(vt * vt) + 2 * (B(p, static_cast<double>(rs.begin_mm)) - bz));
        } else if (rs.end_mm + ext > y) {
          w = std::min(w, static_cast<long double>(vt * vt));
        }
      }
      const long double u = v + a * tt;
      return u * u <= w;
    };
    if (!passes(0.0)) {
      return 0.0;
    }
    double lo = 0.0;
    auto hi = static_cast<double>(s.max_speed_mm_s);
    if (passes(hi)) {
      return hi;
    }
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (passes(mid) ? lo : hi) = mid;
    }
    return lo;
  }
};

// ---- configuration --------------------------------------------------------------------

// @verifies REQ-BR-008
TEST(BrakingPatternsConfig, DefaultsComeFromTheParameters) {
  namespace p = params::br;
  const SupervisionParams s = DefaultSupervisionParams();
  EXPECT_EQ(s.cycle_ms, p::cycle_ms);
  EXPECT_EQ(s.reaction_ms, p::reaction_ms);
  EXPECT_EQ(s.service_offset_mm, p::service_offset_mm);
  EXPECT_EQ(s.lead_4n_ms, p::lead_4n_ms);
  EXPECT_EQ(s.lead_5n_ms, p::lead_5n_ms);
  EXPECT_EQ(s.lead_6n_ms, p::lead_6n_ms);
  EXPECT_EQ(s.release_lead_ms, p::release_lead_ms);
  EXPECT_EQ(s.gradient_error_x10, p::gradient_error_x10);
  EXPECT_EQ(s.gravity_mm_s2, p::gravity_mm_s2);
  EXPECT_EQ(s.max_speed_mm_s, p::max_speed_mm_s);
  EXPECT_EQ(kDefaultProfileCapacity, static_cast<std::size_t>(p::max_profile_entries));
  const PatternCalculator c = Make();
  EXPECT_EQ(c.capacity(), kDefaultProfileCapacity);
  EXPECT_FALSE(c.HasProfile());
}

// @verifies REQ-BR-008
// @verifies REQ-BR-010
TEST(BrakingPatternsConfig, CreateRejectsEachInvalidInput) {
  const SupervisionParams s = DefaultSupervisionParams();
  auto with_train = [&](auto mutate) {
    TrainData t = Emu3();
    mutate(t);
    return PatternCalculator::Create(t, s).error;
  };
  auto with_params = [&](auto mutate) {
    SupervisionParams p = s;
    mutate(p);
    return PatternCalculator::Create(Emu3(), p).error;
  };
  EXPECT_EQ(with_train([](TrainData& t) { t.length_mm = 0; }), CreateError::kTrainLengthInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.length_mm = kMaxTrainLengthMm + 1; }), CreateError::kTrainLengthInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.accel_max_mm_s2 = -1; }), CreateError::kAccelerationInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.beta_e_mm_s2 = 0; }), CreateError::kDecelerationInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.beta_n7_mm_s2 = 0; }), CreateError::kDecelerationInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.beta_n7_mm_s2 = t.beta_e_mm_s2 + 1; }),
            CreateError::kServiceAboveEmergency);
  EXPECT_EQ(with_train([](TrainData& t) { t.beta_n7_mm_s2 = t.beta_e_mm_s2; }), CreateError::kNone);
  EXPECT_EQ(with_train([](TrainData& t) { t.emergency_free_running_ms = -1; }), CreateError::kFreeRunningInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.service_free_running_ms = kMaxTimeMs + 1; }),
            CreateError::kFreeRunningInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.overspeed_mm_s = -1; }), CreateError::kSpeedAllowanceInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.speed_error_ppm = 1'000'001; }), CreateError::kSpeedAllowanceInvalid);
  EXPECT_EQ(with_train([](TrainData& t) { t.speed_error_abs_mm_s = -1; }), CreateError::kSpeedAllowanceInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.cycle_ms = 0; }), CreateError::kTimeInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.reaction_ms = -1; }), CreateError::kTimeInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.service_offset_mm = -1; }), CreateError::kServiceOffsetInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.lead_6n_ms = 0; }), CreateError::kLeadsInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.lead_5n_ms = p.lead_6n_ms; }), CreateError::kLeadsInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.lead_4n_ms = p.lead_5n_ms; }), CreateError::kLeadsInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.release_lead_ms = p.lead_4n_ms; }), CreateError::kLeadsInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.gradient_error_x10 = -1; }), CreateError::kGradientErrorInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.gravity_mm_s2 = 0; }), CreateError::kGravityInvalid);
  EXPECT_EQ(with_params([](SupervisionParams& p) { p.max_speed_mm_s = 0; }), CreateError::kMaxSpeedInvalid);
  EXPECT_EQ(PatternCalculator::Create(Emu3(), s, 0).error, CreateError::kCapacityInvalid);
  EXPECT_EQ(PatternCalculator::Create(Emu3(), s, kMaxProfileCapacity + 1).error, CreateError::kCapacityInvalid);
  EXPECT_FALSE(PatternCalculator::Create(Emu3(), s, 0).calculator.has_value());
}

// @verifies REQ-BR-008
TEST(BrakingPatternsConfig, ToStringNamesEveryValue) {
  EXPECT_STREQ(ToString(Pattern::kEmergency), "EMERGENCY");
  EXPECT_STREQ(ToString(Pattern::kService), "SERVICE");
  EXPECT_STREQ(ToString(CreateError::kNone), "NONE");
  EXPECT_STREQ(ToString(CreateError::kOutOfMemory), "OUT_OF_MEMORY");
  EXPECT_STREQ(ToString(ProfileVerdict::kAccept), "ACCEPT");
  EXPECT_STREQ(ToString(ProfileVerdict::kBrakingNotPositive), "BRAKING_NOT_POSITIVE");
  EXPECT_STREQ(ToString(EvalStatus::kOk), "OK");
  EXPECT_STREQ(ToString(EvalStatus::kInvalidStopLimit), "INVALID_STOP_LIMIT");
  for (int i = 0; i <= static_cast<int>(CreateError::kOutOfMemory); ++i) {
    EXPECT_STRNE(ToString(static_cast<CreateError>(i)), "INVALID");
  }
  for (int i = 0; i <= static_cast<int>(ProfileVerdict::kBrakingNotPositive); ++i) {
    EXPECT_STRNE(ToString(static_cast<ProfileVerdict>(i)), "INVALID");
  }
  for (int i = 0; i <= static_cast<int>(EvalStatus::kInvalidStopLimit); ++i) {
    EXPECT_STRNE(ToString(static_cast<EvalStatus>(i)), "INVALID");
  }
}

// ---- flat line: closed form ------------------------------------------------------------

// The gravity term rounds away from safety in both directions (design note §1).
// @verifies REQ-BR-005
// @verifies REQ-BR-008
TEST(BrakingPatternsFlat, GravityTermRoundsAwayFromSafety) {
  const PatternCalculator c = Make();
  EXPECT_EQ(c.GravityTerm(-10), -10);   // -9.807 -> accelerating term rounded up
  EXPECT_EQ(c.GravityTerm(10), 9);      // +9.807 -> braking credit rounded down
  EXPECT_EQ(c.GravityTerm(-210), -206); // -205.947
  EXPECT_EQ(c.GravityTerm(0), 0);
  EXPECT_EQ(c.GravityTerm(10000), 9807);
  EXPECT_EQ(c.GravityTerm(-10000), -9807);
}

// Run-up time T = cycle + reaction + maximum free-running time of the pattern.
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsFlat, RunUpTimeIncludesFreeRunning) {
  const PatternCalculator c = MakeWith({}, {});
  EXPECT_EQ(c.RunUpTimeMs(Pattern::kEmergency), 200 + 100 + 1'500);
  EXPECT_EQ(c.RunUpTimeMs(Pattern::kService), 200 + 100 + 2'500);
  // level line: G_eff = -gradient_error (-1 permille): b = beta - 10, a = accel + 10
  EXPECT_EQ(c.EffectiveGradientX10(123'456), -10);
  EXPECT_EQ(c.BrakingCapability(Pattern::kEmergency, 0), 990);
  EXPECT_EQ(c.BrakingCapability(Pattern::kService, 0), 890);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 0), 930);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kService, 0), 930);
}

// Hand-computed integer values (brute force over every v of the integer predicate of design
// note §3): 500 m to the stop limit, emu3_d1, level line. Emergency: b = 990, a = 930,
// T = 1800 ms, dv = 1674: 28105 passes ((28105+1674)^2 = 886,788,841 <= 1980 (500000 - 52096)
// = 886,849,920), 28106 does not. Service: stop target 10 m short, b = 890, T = 2800 ms.
// @verifies REQ-BR-001
// @verifies REQ-BR-002
// @verifies REQ-BR-008
TEST(BrakingPatternsFlat, HandComputedValues) {
  const PatternCalculator c = MakeWith({}, {});
  EXPECT_EQ(c.EmergencyPatternSpeed(1'000'000, 1'500'000), 28'105);
  EXPECT_EQ(c.ServicePatternSpeed(1'000'000, 1'500'000), 24'651);
  // the check of the text above
  auto lhs = [](std::int64_t v) { return (v + 1'674) * (v + 1'674); };
  auto rhs = [](std::int64_t v) {
    const std::int64_t d = (2'000 * v * 1'800 + std::int64_t{930} * 1'800 * 1'800 + 1'999'999) / 2'000'000;
    return std::int64_t{1'980} * (500'000 - d);
  };
  EXPECT_EQ(lhs(28'105), 886'788'841);
  EXPECT_EQ(rhs(28'105), 886'849'920);
  EXPECT_LE(lhs(28'105), rhs(28'105));
  EXPECT_GT(lhs(28'106), rhs(28'106));
}

// Flat stop-limit pattern: the floor of the exact real solution (closed form with the
// pattern's b and a) within 1 mm/s, never above it, from 0 to 4 km (both patterns).
// @verifies REQ-BR-001
// @verifies REQ-BR-002
// @verifies REQ-BR-008
TEST(BrakingPatternsFlat, StopPatternEqualsClosedFormFloor) {
  const PatternCalculator c = MakeWith({}, {});
  const std::int64_t limit = 5'000'000;
  for (std::int64_t d = 0; d <= 4'000'000; d += 997) {
    const std::int64_t y = limit - d;
    const std::int64_t ve = c.EmergencyPatternSpeed(y, limit);
    const auto vmax = static_cast<double>(params::br::max_speed_mm_s);
    const double re = std::min(vmax, ClosedForm(930, 990, 1'800, 0, static_cast<double>(d)));
    const std::int64_t vn = c.ServicePatternSpeed(y, limit);
    const double rn = std::min(vmax, ClosedForm(930, 890, 2'800, 0, static_cast<double>(d - 10'000)));
    if (re < 0) {
      EXPECT_EQ(ve, kNoPermittedSpeed) << d;
    } else {
      EXPECT_LE(static_cast<double>(ve), re) << d;
      EXPECT_GE(ve, static_cast<std::int64_t>(std::floor(re)) - 1) << d;
    }
    if (rn < 0 || d < 10'000) {
      EXPECT_EQ(vn, kNoPermittedSpeed) << d;
    } else {
      EXPECT_LE(static_cast<double>(vn), rn) << d;
      EXPECT_GE(vn, static_cast<std::int64_t>(std::floor(rn)) - 1) << d;
    }
  }
}

// Beyond the stop limit nothing is permitted; the service pattern ends service_offset_mm
// short of it.
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsFlat, NothingPermittedAtOrBeyondTheStopTarget) {
  const PatternCalculator c = MakeWith({}, {});
  EXPECT_EQ(c.EmergencyPatternSpeed(2'000'000, 2'000'000), kNoPermittedSpeed);
  EXPECT_EQ(c.EmergencyPatternSpeed(2'000'001, 2'000'000), kNoPermittedSpeed);
  EXPECT_EQ(c.ServicePatternSpeed(1'990'000, 2'000'000), kNoPermittedSpeed);
  EXPECT_EQ(c.ServicePatternSpeed(1'995'000, 2'000'000), kNoPermittedSpeed);
  // far away: capped at max_speed_mm_s
  EXPECT_EQ(c.EmergencyPatternSpeed(0, 5'000'000), params::br::max_speed_mm_s);
}

// ---- gradients ------------------------------------------------------------------------

// A falling gradient (-20 permille) under only the rear part of the train still sets the
// effective gradient: segment [0, 1030 m) applies to fronts in [0, 1090 m).
// @verifies REQ-BR-005
TEST(BrakingPatternsGradient, FallingGradientUnderPartOfTheTrain) {
  const PatternCalculator c = MakeWith({{0, 1'030'000, -200}}, {});
  EXPECT_EQ(c.EffectiveGradientX10(-1), -10);
  EXPECT_EQ(c.EffectiveGradientX10(0), -210);
  EXPECT_EQ(c.EffectiveGradientX10(1'050'000), -210);  // rear 990 m on the gradient, front off it
  EXPECT_EQ(c.EffectiveGradientX10(1'089'999), -210);
  EXPECT_EQ(c.EffectiveGradientX10(1'090'000), -10);
  EXPECT_EQ(c.BrakingCapability(Pattern::kEmergency, 1'050'000), 1'000 - 206);
  EXPECT_EQ(c.BrakingCapability(Pattern::kService, 1'050'000), 900 - 206);
  EXPECT_EQ(c.BrakingCapability(Pattern::kEmergency, 1'090'000), 990);
  // hand-computed (brute force of the integer predicate): a = 920 + 206 = 1126, dv = 2027,
  // b = 794 on [1050, 1090) m and 990 beyond, 350 m to the stop limit
  EXPECT_EQ(c.EmergencyPatternSpeed(1'050'000, 1'400'000), 22'644);
  // the same on a line without the gradient is higher
  const PatternCalculator flat = MakeWith({}, {});
  EXPECT_GT(flat.EmergencyPatternSpeed(1'050'000, 1'400'000), 22'644);
}

// The run-up acceleration takes the steepest falling effective gradient over the run-up
// window [y, y + d_T(max_speed)] (d_T = 151,826 mm for the emergency pattern here).
// @verifies REQ-BR-005
TEST(BrakingPatternsGradient, RunUpAccelerationTakesTheSteepestGradientAhead) {
  const PatternCalculator c = MakeWith({{0, 1'030'000, -200}, {2'000'000, 2'500'000, 150}}, {});
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, -151'826), 1'126);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, -151'827), 930);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 1'089'999), 1'126);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 1'090'000), 930);
  // rising gradient: no credit for the run-up (a = accel_max, never less)
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 2'100'000), 920);
  EXPECT_EQ(c.EffectiveGradientX10(2'100'000), 140);
  EXPECT_EQ(c.BrakingCapability(Pattern::kEmergency, 2'100'000), 1'000 + 137);  // 137.298 down
}

// The true front may lie up to front + rear error behind the supervised front, so the
// run-up window reaches back over the whole position envelope (design note §3).
// @verifies REQ-BR-005 REQ-BR-007
TEST(BrakingPatternsGradient, RunUpWindowCoversThePositionEnvelope) {
  const PatternCalculator c = MakeWith({{0, 1'030'000, -200}}, {});
  // the falling gradient acts on fronts up to 1,090,000 (1,030,000 + 60 m train)
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 1'139'999, 50'000), 1'126);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 1'140'000, 50'000), 930);
  EXPECT_EQ(c.RunUpAcceleration(Pattern::kEmergency, 1'139'999, 0), 930);
  // so the pattern with a 25 m + 25 m envelope is lower just past the gradient
  EXPECT_LT(c.PatternSpeed(Pattern::kEmergency, 1'120'000, 1'500'000, 25'000, 25'000),
            c.PatternSpeed(Pattern::kEmergency, 1'120'000, 1'500'000, 0, 0));
}

// Gradient segments under the whole train and gaps between them: the lowest value wins,
// a gap counts as level.
// @verifies REQ-BR-005
TEST(BrakingPatternsGradient, LowestGradientOverTheTrainIncludingGaps) {
  const PatternCalculator c = MakeWith({{0, 30'000, 50}, {30'000, 50'000, -30}, {70'000, 200'000, 20}}, {});
  EXPECT_EQ(c.EffectiveGradientX10(10'000), -10);    // (-50, 10]: level before 0, 50
  EXPECT_EQ(c.EffectiveGradientX10(65'000), -40);    // (5, 65]: 50, -30, gap -> -30 - 10
  EXPECT_EQ(c.EffectiveGradientX10(109'999), -40);   // (49.999, 109.999]: -30 still under
  EXPECT_EQ(c.EffectiveGradientX10(110'000), -10);   // (50, 110]: gap, 20
  EXPECT_EQ(c.EffectiveGradientX10(130'000), 10);    // (70, 130]: 20 only
}

// ---- restrictions ---------------------------------------------------------------------

// A restriction ahead is a target (braking curve to V_r + overspeed / V_r at its start) and
// a ceiling from the moment the supervised front (or the run-up) reaches its start until the
// rear, extended by the rear error, has left its end.
// @verifies REQ-BR-004
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsRestriction, CeilingUntilTheRearHasLeft) {
  PatternCalculator c = MakeWith({}, {{2'000'000, 2'300'000, 10'000}});
  const std::int64_t limit = 10'000'000;
  PositionEstimate pos{2'100'000, 1'000, 2'000, 8'000, false};
  // inside: emergency ceiling 10000 + 1389 - dv 1674; service 10000 - dv 2604
  Evaluation e = c.Evaluate(pos, limit);
  ASSERT_EQ(e.status, EvalStatus::kOk);
  EXPECT_EQ(e.speeds.v_e, 9'715);
  EXPECT_EQ(e.speeds.v_7n, 7'396);
  // rear = front - 60 m - 2 m: still before 2300 m at front 2361.999 m
  pos.front_mm = 2'361'999;
  e = c.Evaluate(pos, limit);
  EXPECT_EQ(e.speeds.v_e, 9'715);
  EXPECT_EQ(e.speeds.v_7n, 7'396);
  EXPECT_EQ(c.EmergencyPatternSpeed(2'362'999, limit, 1'000, 2'000), 9'715);
  // rear error 0: released 2 m earlier
  EXPECT_EQ(c.EmergencyPatternSpeed(2'361'000, limit, 1'000, 0), params::br::max_speed_mm_s);
  // rear has left: no ceiling any more (the stop limit is 7.6 km away)
  pos.front_mm = 2'362'000;
  e = c.Evaluate(pos, limit);
  EXPECT_EQ(e.speeds.v_e, params::br::max_speed_mm_s);
  // supervised front at the start: ceiling
  EXPECT_EQ(c.EmergencyPatternSpeed(2'000'000, limit), 9'715);
  EXPECT_EQ(c.ServicePatternSpeed(2'000'000, limit), 7'396);
}

// Approaching a restriction: the closed-form braking curve to V_r + overspeed (emergency) /
// V_r (service) at its start, until the run-up reaches it; then the ceiling.
// @verifies REQ-BR-004
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsRestriction, ApproachFollowsTheBrakingCurveToTheLimit) {
  const PatternCalculator c = MakeWith({}, {{3'000'000, 3'300'000, 10'000}});
  const std::int64_t limit = 20'000'000;
  for (std::int64_t d = 0; d <= 3'000'000; d += 1'009) {
    const std::int64_t y = 3'000'000 - d;
    const std::int64_t ve = c.EmergencyPatternSpeed(y, limit);
    const std::int64_t vn = c.ServicePatternSpeed(y, limit);
    const double re = std::max(ClosedForm(930, 990, 1'800, 11'389, static_cast<double>(d)), 11'389.0 - 1'674.0);
    const double rn = std::max(ClosedForm(930, 890, 2'800, 10'000, static_cast<double>(d)), 10'000.0 - 2'604.0);
    EXPECT_LE(static_cast<double>(ve), re) << d;
    EXPECT_GE(ve, static_cast<std::int64_t>(std::floor(re)) - 1) << d;
    EXPECT_LE(static_cast<double>(vn), rn) << d;
    EXPECT_GE(vn, static_cast<std::int64_t>(std::floor(rn)) - 1) << d;
  }
}

// A short restriction inside the run-up is a ceiling even though the run-up ends beyond it
// (the run-up never "jumps over" a restriction; design deviation noted in patterns.cpp).
// @verifies REQ-BR-004
TEST(BrakingPatternsRestriction, ShortRestrictionInsideTheRunUpIsACeiling) {
  const PatternCalculator c = MakeWith({}, {{1'010'000, 1'011'000, 5'000}});
  const std::int64_t limit = 20'000'000;
  // 10 m before it: the run-up (>= 1.5 m at v = 0) soon reaches it
  EXPECT_EQ(c.EmergencyPatternSpeed(1'000'000, limit), 5'000 + 1'389 - 1'674);
  EXPECT_EQ(c.ServicePatternSpeed(1'000'000, limit), 5'000 - 2'604);
}

// Overlapping ceilings and targets: the lowest wins; restrictions behind the train do not count.
// @verifies REQ-BR-004
TEST(BrakingPatternsRestriction, LowestOfSeveralRestrictions) {
  const PatternCalculator c =
      MakeWith({}, {{0, 100'000, 4'000}, {1'000'000, 1'100'000, 20'000}, {1'100'000, 1'200'000, 15'000}});
  const std::int64_t limit = 20'000'000;
  EXPECT_EQ(c.EmergencyPatternSpeed(1'090'000, limit), 15'000 + 1'389 - 1'674);  // run-up reaches 1100 m
  // 50 m before the lower one: its braking curve, below the 20000 ceiling
  const std::int64_t v = c.EmergencyPatternSpeed(1'050'000, limit);
  EXPECT_LT(v, 20'000 + 1'389 - 1'674);
  EXPECT_LE(static_cast<double>(v), ClosedForm(930, 990, 1'800, 16'389, 50'000));
  EXPECT_GE(static_cast<double>(v), ClosedForm(930, 990, 1'800, 16'389, 50'000) - 2);
  EXPECT_EQ(c.EmergencyPatternSpeed(1'250'000, limit, 0, 0), 15'000 + 1'389 - 1'674);  // rear in it
  EXPECT_EQ(c.EmergencyPatternSpeed(1'260'000, limit, 0, 0), params::br::max_speed_mm_s);
}

// ---- supervised speed, standstill, one cycle ------------------------------------------

// v_s = v_m + ceil(v_m * 2500 / 1e6) + 174, at standstill too (a creeping train reads 0).
// @verifies REQ-BR-007
TEST(BrakingPatternsSpeed, SupervisedSpeedAddsTheAllowance) {
  const PatternCalculator c = MakeWith({}, {});
  EXPECT_EQ(c.SupervisedSpeed(20'000), 20'000 + 50 + 174);
  EXPECT_EQ(c.SupervisedSpeed(20'001), 20'001 + 51 + 174);  // 50.0025 rounded up
  EXPECT_EQ(c.SupervisedSpeed(0, true), 174);
  EXPECT_EQ(c.SupervisedSpeed(0, false), 174);
  EXPECT_EQ(c.SupervisedSpeed(10, true), 10 + 1 + 174);
  EXPECT_EQ(c.SupervisedSpeed(-20'000), 20'000 + 50 + 174);
  const Evaluation e = c.Evaluate(PositionEstimate{0, 0, 0, 30'000, false}, 3'000'000);
  EXPECT_EQ(e.speeds.v_s, 30'000 + 75 + 174);
}

// A train standing closer to its stop limit than the run-up from rest (cycle, reaction and
// free-running time at full traction, then braking) must not start: the emergency pattern
// permits nothing there, so the brake is held at standstill (found by the worst-case margin
// analysis: with a pattern speed of 0 such a train could restart and overrun by ~5 m).
// @verifies REQ-BR-001 REQ-BR-009
TEST(BrakingPatternsStandstill, NoRestartWithinTheRunUpOfTheStopLimit) {
  const PatternCalculator c = MakeWith({}, {});
  const std::int64_t limit = 2'000'000;
  // run-up from rest: a = 930, T = 1.8 s: d_T = 1,507 mm, v_T = 1,674 mm/s, braking
  // 1,674^2 / (2 * 990) = 1,416 mm: nothing is permitted within about 2.9 m of L
  EXPECT_EQ(c.EmergencyPatternSpeed(limit - 2'800, limit), kNoPermittedSpeed);
  EXPECT_GE(c.EmergencyPatternSpeed(limit - 3'000, limit), 0);
  const Evaluation e = c.Evaluate(PositionEstimate{limit - 2'800, 0, 0, 0, true}, limit);
  Supervisor sup;
  EXPECT_EQ(sup.Step(e.speeds, DriverInputs{true, false, false}).level, BrakeLevel::kEmergency);
}

// Without a usable stop limit the stop limit is the supervised front: no speed is permitted
// (not even standing, since a start would run up beyond it), so the emergency brake is
// commanded and held, at standstill too (REQ-BR-012).
// @verifies REQ-BR-012
TEST(BrakingPatternsStandstill, NoStopLimitSupervisesStandstill) {
  const PatternCalculator c = MakeWith({}, {{0, 10'000'000, 30'000}});
  PositionEstimate pos{500'000, 1'000, 1'000, 0, true};
  Evaluation e = c.Evaluate(pos, std::nullopt);
  ASSERT_EQ(e.status, EvalStatus::kOk);
  EXPECT_EQ(e.speeds.v_s, 174);
  EXPECT_EQ(e.speeds.v_e, kNoPermittedSpeed);
  EXPECT_EQ(e.speeds.v_7n, kNoPermittedSpeed);
  EXPECT_EQ(e.speeds.v_release, kNoPermittedSpeed);
  Supervisor sup;
  EXPECT_EQ(sup.Step(e.speeds, DriverInputs{true, false, false}).level, BrakeLevel::kEmergency);
  // standstill, handle and reset release the latch, but the brake is commanded again at once
  EXPECT_EQ(sup.Step(e.speeds, DriverInputs{true, true, true}).level, BrakeLevel::kEmergency);
  pos.standstill = false;  // speed zero but not yet for the standstill time
  e = c.Evaluate(pos, std::nullopt);
  EXPECT_EQ(e.speeds.v_s, 174);
  EXPECT_EQ(e.speeds.v_e, kNoPermittedSpeed);
  EXPECT_EQ(sup.Step(e.speeds, DriverInputs{}).level, BrakeLevel::kEmergency);
  pos.speed_mm_s = 1'000;
  e = c.Evaluate(pos, std::nullopt);
  EXPECT_EQ(e.speeds.v_e, kNoPermittedSpeed);
  EXPECT_GT(e.speeds.v_s, e.speeds.v_e);
  // with a stop limit far ahead the same train may run
  e = c.Evaluate(pos, 3'000'000);
  EXPECT_GT(e.speeds.v_e, e.speeds.v_s);
}

// One cycle: v_e and v_7n at x_s = x_m + e_f, the service pattern at x_s + ceil(v_s lead / 1000)
// for the 6N, 5N, 4N and release leads; ordered when approaching the stop limit.
// @verifies REQ-BR-003
// @verifies REQ-BR-007
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsEvaluate, LeadPointsUseTheServicePatternAhead) {
  const PatternCalculator c = MakeWith({{1'200'000, 1'400'000, -150}}, {{1'500'000, 1'600'000, 8'000}});
  const PositionEstimate pos{1'000'000, 500, 700, 20'000, false};
  const std::int64_t limit = 1'800'000;
  const Evaluation e = c.Evaluate(pos, limit);
  ASSERT_EQ(e.status, EvalStatus::kOk);
  const std::int64_t xs = 1'000'500;
  const std::int64_t vs = 20'224;
  EXPECT_EQ(e.speeds.v_s, vs);
  EXPECT_EQ(e.speeds.v_e, c.EmergencyPatternSpeed(xs, limit, 500, 700));
  EXPECT_EQ(e.speeds.v_7n, c.ServicePatternSpeed(xs, limit, 500, 700));
  EXPECT_EQ(e.speeds.v_6n, c.ServicePatternSpeed(xs + 40'448, limit, 500, 700));
  EXPECT_EQ(e.speeds.v_5n, c.ServicePatternSpeed(xs + 60'672, limit, 500, 700));
  EXPECT_EQ(e.speeds.v_4n, c.ServicePatternSpeed(xs + 80'896, limit, 500, 700));
  EXPECT_EQ(e.speeds.v_release, c.ServicePatternSpeed(xs + 101'120, limit, 500, 700));
  EXPECT_GE(e.speeds.v_e, e.speeds.v_7n);
  EXPECT_GT(e.speeds.v_7n, e.speeds.v_6n);
  EXPECT_GT(e.speeds.v_6n, e.speeds.v_5n);
  EXPECT_GT(e.speeds.v_5n, e.speeds.v_4n);
  EXPECT_GT(e.speeds.v_4n, e.speeds.v_release);
  // the front error moves the supervised front
  const Evaluation e0 = c.Evaluate(PositionEstimate{1'000'000, 0, 700, 20'000, false}, limit);
  EXPECT_GT(e0.speeds.v_e, e.speeds.v_e);
}

// Invalid inputs and a missing profile: typed status, no pattern speed permitted
// (kNoPermittedSpeed), so the supervisor commands the emergency brake, at standstill too.
// @verifies REQ-BR-008
TEST(BrakingPatternsEvaluate, InvalidInputsFailSafe) {
  PatternCalculator c = Make();
  const PositionEstimate ok{0, 0, 0, 0, true};
  Evaluation e = c.Evaluate(ok, 1'000'000);
  EXPECT_EQ(e.status, EvalStatus::kNoProfile);
  EXPECT_EQ(e.speeds.v_e, kNoPermittedSpeed);
  EXPECT_EQ(e.speeds.v_release, kNoPermittedSpeed);
  EXPECT_EQ(e.speeds.v_s, 174);
  Supervisor sup;
  EXPECT_EQ(sup.Step(e.speeds, DriverInputs{true, false, false}).level, BrakeLevel::kEmergency);
  ASSERT_EQ(c.SetProfile({}, {}).verdict, ProfileVerdict::kAccept);
  EXPECT_EQ(c.Evaluate(ok, 1'000'000).status, EvalStatus::kOk);
  auto status = [&](PositionEstimate p, std::optional<std::int64_t> l) { return c.Evaluate(p, l).status; };
  EXPECT_EQ(status({kMaxPositionMm + 1, 0, 0, 0, false}, 0), EvalStatus::kInvalidPosition);
  EXPECT_EQ(status({0, -1, 0, 0, false}, 0), EvalStatus::kInvalidPosition);
  EXPECT_EQ(status({0, 0, kMaxPositionErrorMm + 1, 0, false}, 0), EvalStatus::kInvalidPosition);
  EXPECT_EQ(status({0, 0, 0, -1, false}, 0), EvalStatus::kInvalidSpeed);
  EXPECT_EQ(status({0, 0, 0, kMaxMeasuredSpeedMmS + 1, false}, 0), EvalStatus::kInvalidSpeed);
  EXPECT_EQ(status({0, 0, 0, 0, false}, -kMaxPositionMm - 1), EvalStatus::kInvalidStopLimit);
  EXPECT_EQ(status({kMaxPositionMm, kMaxPositionErrorMm, kMaxPositionErrorMm, kMaxMeasuredSpeedMmS, false},
                   kMaxPositionMm),
            EvalStatus::kOk);
  e = c.Evaluate({0, 0, 0, -5'000, false}, 1'000'000);
  EXPECT_EQ(e.speeds.v_e, kNoPermittedSpeed);
  EXPECT_GT(e.speeds.v_s, e.speeds.v_e);
  // helpers: out-of-range arguments permit nothing
  EXPECT_EQ(c.EmergencyPatternSpeed(0, kMaxPositionMm + 1), kNoPermittedSpeed);
  EXPECT_EQ(c.EmergencyPatternSpeed(0, 1'000'000, -1, 0), kNoPermittedSpeed);
  EXPECT_EQ(c.EmergencyPatternSpeed(kMaxPositionMm + kMaxPositionErrorMm + 1, kMaxPositionMm),
            kNoPermittedSpeed);
}

// ---- profile validation: one test per reason ------------------------------------------

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, AcceptsAFullProfile) {
  PatternCalculator c = Make(Emu3(), 4);
  const std::vector<GradientSegment> g{{0, 10, 5}, {10, 20, -5}, {30, 40, 0}, {40, 50, 7}};
  const std::vector<RestrictionSegment> r{{0, 10, 5}, {10, 20, 6}, {30, 40, 7}, {40, 50, 8}};
  EXPECT_EQ(c.SetProfile(g, r).verdict, ProfileVerdict::kAccept);
  EXPECT_TRUE(c.HasProfile());
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsTooManyGradients) {
  PatternCalculator c = Make(Emu3(), 4);
  const std::vector<GradientSegment> g{{0, 10, 5}, {10, 20, -5}, {30, 40, 0}, {40, 50, 7}, {50, 60, 7}};
  EXPECT_EQ(c.SetProfile(g, {}).verdict, ProfileVerdict::kTooManyGradients);
  EXPECT_FALSE(c.HasProfile());
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsTooManyRestrictions) {
  PatternCalculator c = Make(Emu3(), 2);
  const std::vector<RestrictionSegment> r{{0, 10, 5}, {10, 20, 6}, {30, 40, 7}};
  const ProfileResult res = c.SetProfile({}, r);
  EXPECT_EQ(res.verdict, ProfileVerdict::kTooManyRestrictions);
  EXPECT_TRUE(res.in_restrictions);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsPositionOutOfRange) {
  PatternCalculator c = Make();
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{-kMaxPositionMm - 1, 0, 0}}, {}).verdict,
            ProfileVerdict::kPositionOutOfRange);
  const ProfileResult res = c.SetProfile({}, std::vector<RestrictionSegment>{{0, 10, 5}, {10, kMaxPositionMm + 1, 5}});
  EXPECT_EQ(res.verdict, ProfileVerdict::kPositionOutOfRange);
  EXPECT_TRUE(res.in_restrictions);
  EXPECT_EQ(res.entry, 1U);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsEmptySegment) {
  PatternCalculator c = Make();
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{10, 10, 0}}, {}).verdict, ProfileVerdict::kEmptySegment);
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{10, 5, 5}}).verdict, ProfileVerdict::kEmptySegment);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsUnsortedSegments) {
  PatternCalculator c = Make();
  const ProfileResult res = c.SetProfile(std::vector<GradientSegment>{{100, 200, 0}, {0, 50, 0}}, {});
  EXPECT_EQ(res.verdict, ProfileVerdict::kUnsorted);
  EXPECT_EQ(res.entry, 1U);
  EXPECT_FALSE(res.in_restrictions);
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{100, 200, 5}, {0, 50, 5}}).verdict,
            ProfileVerdict::kUnsorted);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsOverlappingSegments) {
  PatternCalculator c = Make();
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{0, 100, 0}, {99, 200, 0}}, {}).verdict,
            ProfileVerdict::kOverlap);
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{0, 100, 5}, {99, 200, 5}}).verdict,
            ProfileVerdict::kOverlap);
  // touching is fine
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{0, 100, 0}, {100, 200, 0}}, {}).verdict,
            ProfileVerdict::kAccept);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsGradientOutOfRange) {
  PatternCalculator c = Make();
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{0, 100, kMaxGradientX10 + 1}}, {}).verdict,
            ProfileVerdict::kGradientOutOfRange);
  EXPECT_EQ(c.SetProfile(std::vector<GradientSegment>{{0, 100, kMaxGradientX10}}, {}).verdict,
            ProfileVerdict::kAccept);
}

// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsLimitOutOfRange) {
  PatternCalculator c = Make();
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{0, 100, 0}}).verdict, ProfileVerdict::kLimitOutOfRange);
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{0, 100, kMaxLimitMmS + 1}}).verdict,
            ProfileVerdict::kLimitOutOfRange);
  EXPECT_EQ(c.SetProfile({}, std::vector<RestrictionSegment>{{0, 100, 1}}).verdict, ProfileVerdict::kAccept);
}

// b = beta_n7 + floor(G_eff * 9807 / 10000) must be > 0: G_eff = -917 gives 900 - 900 = 0
// (refused), -916 gives 1 (accepted). A refused profile leaves no profile (standstill).
// @verifies REQ-BR-005
// @verifies REQ-BR-008
TEST(BrakingPatternsProfile, RejectsBrakingNotPositive) {
  PatternCalculator c = Make();
  ASSERT_EQ(c.SetProfile({}, {}).verdict, ProfileVerdict::kAccept);
  const ProfileResult res = c.SetProfile(std::vector<GradientSegment>{{0, 10, 5}, {100, 200, -907}}, {});
  EXPECT_EQ(res.verdict, ProfileVerdict::kBrakingNotPositive);
  EXPECT_EQ(res.entry, 1U);
  EXPECT_FALSE(c.HasProfile());
  EXPECT_EQ(c.Evaluate(PositionEstimate{0, 0, 0, 0, true}, 1'000'000).status, EvalStatus::kNoProfile);
  ASSERT_EQ(c.SetProfile(std::vector<GradientSegment>{{100, 200, -906}}, {}).verdict, ProfileVerdict::kAccept);
  EXPECT_EQ(c.BrakingCapability(Pattern::kService, 150), 1);
  EXPECT_EQ(c.BrakingCapability(Pattern::kEmergency, 150), 101);
}

// ---- runtime rules --------------------------------------------------------------------

// @verifies REQ-BR-008
TEST(BrakingPatternsRuntime, NoAllocationAfterCreate) {
  PatternCalculator c = Make();
  std::vector<GradientSegment> g;
  std::vector<RestrictionSegment> r;
  for (std::int64_t i = 0; i < 128; ++i) {
    g.push_back({i * 40'000, i * 40'000 + 30'000, (i % 7 - 3) * 50});
    r.push_back({i * 40'000, i * 40'000 + 20'000, 10'000 + (i % 5) * 3'000});
  }
  Supervisor sup;
  testing::StartCountingAllocations();
  const ProfileResult res = c.SetProfile(g, r);
  std::int64_t sum = 0;
  for (std::int64_t x = 0; x < 5'000'000; x += 50'000) {
    const Evaluation e = c.Evaluate(PositionEstimate{x, 1'000, 1'000, 15'000, false}, x + 1'000'000);
    sum += e.speeds.v_e + sup.Step(e.speeds, DriverInputs{}).emergency_latched;
    sum += c.EmergencyPatternSpeed(x, x + 500'000) + c.ServicePatternSpeed(x, x + 500'000);
  }
  const std::size_t allocations = testing::StopCountingAllocations();
  EXPECT_EQ(res.verdict, ProfileVerdict::kAccept);
  EXPECT_EQ(allocations, 0U);
  EXPECT_GT(sum, 0);
}

// Same inputs, same outputs: two calculators, repeated evaluations, in any order.
// @verifies REQ-BR-008
TEST(BrakingPatternsRuntime, Deterministic) {
  const std::vector<GradientSegment> g{{100'000, 400'000, -250}, {400'000, 900'000, 120}, {1'200'000, 1'300'000, -80}};
  const std::vector<RestrictionSegment> r{{500'000, 700'000, 12'000}, {1'000'000, 1'050'000, 7'000}};
  const PatternCalculator a = MakeWith(g, r);
  const PatternCalculator b = MakeWith(g, r);
  std::mt19937_64 rng(42);
  std::vector<PatternSpeeds> first;
  for (int i = 0; i < 300; ++i) {
    const PositionEstimate pos{static_cast<std::int64_t>(rng() % 2'000'000), static_cast<std::int64_t>(rng() % 5'000),
                               static_cast<std::int64_t>(rng() % 5'000), static_cast<std::int64_t>(rng() % 40'000),
                               false};
    const std::int64_t limit = static_cast<std::int64_t>(rng() % 2'500'000);
    const Evaluation ea = a.Evaluate(pos, limit);
    const Evaluation eb = b.Evaluate(pos, limit);
    const Evaluation ea2 = a.Evaluate(pos, limit);
    for (const Evaluation* e : {&eb, &ea2}) {
      EXPECT_EQ(ea.speeds.v_s, e->speeds.v_s);
      EXPECT_EQ(ea.speeds.v_e, e->speeds.v_e);
      EXPECT_EQ(ea.speeds.v_7n, e->speeds.v_7n);
      EXPECT_EQ(ea.speeds.v_6n, e->speeds.v_6n);
      EXPECT_EQ(ea.speeds.v_5n, e->speeds.v_5n);
      EXPECT_EQ(ea.speeds.v_4n, e->speeds.v_4n);
      EXPECT_EQ(ea.speeds.v_release, e->speeds.v_release);
    }
  }
}

// ---- properties -----------------------------------------------------------------------

// Approaching a stop limit on a line of constant gradient, the pattern speed is
// non-increasing with every mm closer (sampled every 37 mm over 3 km, both patterns, three
// gradients).
// @verifies REQ-BR-001
// @verifies REQ-BR-002
TEST(BrakingPatternsProperty, NonIncreasingTowardsTheStopLimit) {
  for (std::int64_t grad : {0, -300, 250}) {
    std::vector<GradientSegment> g;
    if (grad != 0) {
      g.push_back({-1'000'000, 10'000'000, grad});
    }
    const PatternCalculator c = MakeWith(g, {});
    const std::int64_t limit = 4'000'000;
    std::int64_t prev_e = std::numeric_limits<std::int64_t>::max();
    std::int64_t prev_n = prev_e;
    for (std::int64_t y = 1'000'000; y <= limit + 100; y += 37) {
      const std::int64_t ve = c.EmergencyPatternSpeed(y, limit);
      const std::int64_t vn = c.ServicePatternSpeed(y, limit);
      ASSERT_LE(ve, prev_e) << grad << " " << y;
      ASSERT_LE(vn, prev_n) << grad << " " << y;
      prev_e = ve;
      prev_n = vn;
    }
    EXPECT_EQ(prev_e, kNoPermittedSpeed);
  }
}

// Approaching a restriction (before its start) the pattern is non-increasing as well.
// @verifies REQ-BR-004
TEST(BrakingPatternsProperty, NonIncreasingTowardsARestriction) {
  const PatternCalculator c = MakeWith({}, {{3'000'000, 3'100'000, 6'000}});
  std::int64_t prev = std::numeric_limits<std::int64_t>::max();
  for (std::int64_t y = 0; y <= 3'000'000; y += 41) {
    const std::int64_t v = c.EmergencyPatternSpeed(y, 9'000'000);
    ASSERT_LE(v, prev) << y;
    prev = v;
  }
  EXPECT_EQ(prev, 6'000 + 1'389 - 1'674);
}

// Randomised comparison with the double-precision reference (real arithmetic, real gravity
// term, no floors or ceilings): the integer pattern is never above the real one (proof
// obligation BR-a2) and below it by no more than the roundings can explain (GapBound); the
// effective gradient is identical.
// @verifies REQ-BR-001
// @verifies REQ-BR-002
// @verifies REQ-BR-004
// @verifies REQ-BR-005
// @verifies REQ-BR-008
TEST(BrakingPatternsProperty, NeverAboveTheRealPatternAndClose) {
  std::mt19937_64 rng(20240611);
  auto uniform = [&](std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
  };
  const TrainData trains[] = {Emu3(), Dmu2(), Emu10()};
  double worst_gap = 0;
  int compared = 0;
  for (int profile = 0; profile < 300; ++profile) {
    const TrainData& t = trains[profile % 3];
    std::vector<GradientSegment> g;
    std::int64_t x = uniform(-300'000, 200'000);
    for (std::int64_t n = uniform(0, 8); n > 0; --n) {
      x += uniform(0, 1) * uniform(1, 300'000);  // gap or not
      const std::int64_t len = uniform(1, 800'000);
      g.push_back({x, x + len, uniform(-350, 350)});
      x += len;
    }
    std::vector<RestrictionSegment> r;
    x = uniform(0, 1'000'000);
    for (std::int64_t n = uniform(0, 4); n > 0; --n) {
      x += uniform(0, 1) * uniform(1, 1'500'000);
      const std::int64_t len = uniform(1'000, 600'000);
      r.push_back({x, x + len, uniform(4'000, 35'000)});
      x += len;
    }
    const PatternCalculator c = MakeWith(g, r, t);
    const Reference ref(t, g, r);
    for (int k = 0; k < 25; ++k) {
      const std::int64_t limit = uniform(200'000, 6'000'000);
      const std::int64_t y = uniform(-400'000, limit + 1'000);
      const std::int64_t ef = uniform(0, 50'000);
      const std::int64_t er = uniform(0, 50'000);
      ASSERT_EQ(c.EffectiveGradientX10(y), ref.Geff(y)) << profile << " " << y;
      for (Pattern p : {Pattern::kEmergency, Pattern::kService}) {
        const std::int64_t v = c.PatternSpeed(p, y, limit, ef, er);
        const double real = ref.Speed(p, y, limit, t.length_mm + ef + er);
        ASSERT_LE(static_cast<double>(v), real + 1e-6) << profile << " " << ToString(p) << " y " << y << " L " << limit;
        const double bound = ref.GapBound(p, real);
        EXPECT_LE(real - static_cast<double>(v), bound) << profile << " " << ToString(p) << " y " << y << " L " << limit;
        worst_gap = std::max(worst_gap, (real - static_cast<double>(v)) / bound);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 300 * 25 * 2);
  RecordProperty("worst_gap_over_bound", std::to_string(worst_gap));
}

// A pseudo-random line around the origin for the ordering properties: gradient segments
// (gaps level), line limits over most of it and temporary restrictions cut into them, sorted
// and non-overlapping as SetProfile takes them; the limits from walking pace to 35 m/s, many
// near the speeds the properties draw.
struct RandomLine {
  std::vector<GradientSegment> gradients;
  std::vector<RestrictionSegment> restrictions;
};
template <class Uniform>
RandomLine MakeRandomLine(Uniform& uniform) {
  RandomLine l;
  std::int64_t x = uniform(-400'000, 0);
  for (std::int64_t n = uniform(0, 10); n > 0; --n) {
    x += uniform(0, 1) * uniform(1, 200'000);
    const std::int64_t len = uniform(1, 400'000);
    l.gradients.push_back({x, x + len, uniform(-350, 350)});
    x += len;
  }
  x = uniform(-300'000, 0);
  for (std::int64_t n = uniform(0, 12); n > 0; --n) {
    x += uniform(0, 3) == 0 ? uniform(1, 150'000) : 0;  // mostly contiguous, like line limits
    const std::int64_t len = uniform(0, 1) == 0 ? uniform(1'000, 80'000) : uniform(1, 400'000);
    l.restrictions.push_back({x, x + len, uniform(0, 1) == 0 ? uniform(1'000, 12'000) : uniform(1'000, 35'000)});
    x += len;
  }
  return l;
}

// The emergency pattern is never below the service pattern at the supervised front (v_e >=
// v_7n), on pseudo-random lines, positions, errors, speeds and stop limits, for the train types
// and for train data drawn under the design rule (beta_n7 <= beta_e) with the emergency
// free-running time not above the service one (as every train type of spec/trains has it; Create
// does not require it, and with a longer emergency free-running time v_e < v_7n does occur): the
// emergency pattern brakes at least as hard, runs up for no longer (so no faster and no
// farther), targets the stop limit itself rather than service_offset short of it and each
// restriction at its limit plus the overspeed allowance. So a concrete state never has v_s
// above v_e and not above v_7n (the br vectors that ask for it are not replayed through the
// on-board unit: units/tests/onboard/test_onboard_replay.cpp).
// @verifies REQ-BR-010
TEST(BrakingPatternsProperty, EmergencyNeverBelowService) {
  std::mt19937_64 rng(20261127);
  auto uniform = [&](std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
  };
  int compared = 0;
  int service_exceeded_alone = 0;  // v_s between v_7n and v_e: both patterns met
  for (int profile = 0; profile < 400; ++profile) {
    TrainData t = std::array<TrainData, 3>{Emu3(), Dmu2(), Emu10()}[static_cast<std::size_t>(profile % 4 % 3)];
    if (profile % 4 == 3) {
      t.beta_e_mm_s2 = uniform(500, 1'500);
      t.beta_n7_mm_s2 = uniform(300, t.beta_e_mm_s2);
      t.service_free_running_ms = uniform(500, 4'000);
      t.emergency_free_running_ms = uniform(0, t.service_free_running_ms);
      t.accel_max_mm_s2 = uniform(0, 1'500);
      t.overspeed_mm_s = uniform(0, 3'000);
    }
    const RandomLine l = MakeRandomLine(uniform);
    PatternCalculator c = Make(t);
    if (c.SetProfile(l.gradients, l.restrictions).verdict != ProfileVerdict::kAccept) {
      continue;  // a falling gradient steeper than the drawn braking: no profile to supervise
    }
    for (int k = 0; k < 40; ++k) {
      const PositionEstimate pos{uniform(-300'000, 1'500'000), uniform(0, 30'000), uniform(0, 30'000),
                                 uniform(0, 35'000), false};
      const Evaluation e = c.Evaluate(pos, pos.front_mm + uniform(-10'000, 1'500'000));
      ASSERT_EQ(e.status, EvalStatus::kOk);
      ASSERT_GE(e.speeds.v_e, e.speeds.v_7n) << profile << " " << k << " front " << pos.front_mm;
      service_exceeded_alone += e.speeds.v_s > e.speeds.v_7n && e.speeds.v_s <= e.speeds.v_e ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_GT(compared, 10'000);
  EXPECT_GT(service_exceeded_alone, 100);
}

// Of the service pattern's five points (x_s and the 6N, 5N, 4N and release leads) the ones v_s
// exceeds form a prefix and a suffix, never a run with a point not exceeded on either side,
// wherever the five lie within the ceiling extension (length + front error + rear error) and
// share one run-up acceleration. Between y1 < y2 < y3: the stop limit or a restriction ahead
// that is exceeded at y2 is exceeded at y3 (nearer, or a ceiling by then); a restriction's
// ceiling exceeded at y2 but not at y1 is not reached at y1 (begin beyond y1's run-up), and not
// at y3 only once y3 has passed end + extension, farther than the extension from y1. So the br
// vectors that ask for such a run have no concrete state at a speed whose release lead is
// shorter than the train (units/tests/onboard/test_onboard_replay.cpp: 5 m/s, 26.5 m against
// 60 m).
// @verifies REQ-BR-004
TEST(BrakingPatternsProperty, NoExceededRunBetweenLeadsWithinTheCeilingExtension) {
  std::mt19937_64 rng(20261128);
  auto uniform = [&](std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
  };
  const SupervisionParams s = DefaultSupervisionParams();
  const std::array<std::int64_t, 5> leads{0, s.lead_6n_ms, s.lead_5n_ms, s.lead_4n_ms, s.release_lead_ms};
  int checked = 0;
  int prefix_and_suffix = 0;  // exceeded at x_s and at the release lead, not between
  int prefix_alone = 0;       // exceeded at x_s, not at the release lead
  for (int profile = 0; profile < 400; ++profile) {
    const TrainData t = std::array<TrainData, 3>{Emu3(), Dmu2(), Emu10()}[static_cast<std::size_t>(profile % 3)];
    const RandomLine l = MakeRandomLine(uniform);
    PatternCalculator c = Make(t);
    if (c.SetProfile(l.gradients, l.restrictions).verdict != ProfileVerdict::kAccept) {
      continue;
    }
    for (int k = 0; k < 100; ++k) {
      const PositionEstimate pos{uniform(-300'000, 1'500'000), uniform(0, 20'000), uniform(0, 20'000),
                                 uniform(0, 12'000), false};
      const Evaluation e = c.Evaluate(pos, pos.front_mm + uniform(0, 1'500'000));
      ASSERT_EQ(e.status, EvalStatus::kOk);
      const std::int64_t x_s = pos.front_mm + pos.front_error_mm;
      const std::int64_t envelope = pos.front_error_mm + pos.rear_error_mm;
      std::array<std::int64_t, 5> points{};
      std::transform(leads.begin(), leads.end(), points.begin(),
                     [&](std::int64_t lead) { return x_s + (e.speeds.v_s * lead + 999) / 1'000; });
      const bool one_run_up = std::all_of(points.begin(), points.end(), [&](std::int64_t y) {
        return c.RunUpAcceleration(Pattern::kService, y, envelope) ==
               c.RunUpAcceleration(Pattern::kService, x_s, envelope);
      });
      if (points[4] - x_s >= t.length_mm + envelope || !one_run_up) {
        continue;
      }
      const std::array<bool, 5> ex{e.speeds.v_s > e.speeds.v_7n, e.speeds.v_s > e.speeds.v_6n,
                                   e.speeds.v_s > e.speeds.v_5n, e.speeds.v_s > e.speeds.v_4n,
                                   e.speeds.v_s > e.speeds.v_release};
      // no exceeded point between the first and the last point not exceeded
      const auto first_clear = std::find(ex.begin(), ex.end(), false);
      const auto last_clear = std::find(ex.rbegin(), ex.rend(), false).base();
      ASSERT_TRUE(first_clear == ex.end() || std::find(first_clear, last_clear, true) == last_clear)
          << profile << " " << k << " front " << pos.front_mm;
      prefix_and_suffix += ex[0] && ex[4] && std::count(ex.begin(), ex.end(), false) > 0 ? 1 : 0;
      prefix_alone += ex[0] && !ex[4] ? 1 : 0;
      ++checked;
    }
  }
  EXPECT_GT(checked, 30'000);
  EXPECT_GT(prefix_and_suffix, 10);
  EXPECT_GT(prefix_alone, 100);
}

// The scenario of bench_braking (REQ-BR-013: 5 km look-ahead, 30 gradient changes and 20
// restrictions, stop limit 4.5 km ahead; the time figure is the benchmark's, no test asserts
// wall-clock time): every cycle of the O(log n) envelope agrees with the straightforward
// reference, and the full-capacity profile (128 + 128 entries) is accepted and evaluated.
// @verifies REQ-BR-013
// @verifies REQ-BR-008
TEST(BrakingPatternsProperty, BenchmarkScenarioAgreesWithTheReference) {
  constexpr std::int64_t kOrigin = 10'000'000;
  constexpr std::int64_t kLookAhead = params::br::lookahead_mm;
  std::vector<GradientSegment> g;
  for (std::int64_t i = 0; i < 30; ++i) {
    const std::int64_t begin = kOrigin - 200'000 + i * (kLookAhead + 200'000) / 30;
    const std::int64_t end = begin + (kLookAhead + 200'000) / 30 - (i % 4 == 0 ? 20'000 : 0);
    g.push_back({begin, end, ((i * 37) % 51 - 25) * 10});
  }
  std::vector<RestrictionSegment> r;
  for (std::int64_t i = 0; i < 20; ++i) {
    const std::int64_t begin = kOrigin + 100'000 + i * 220'000;
    r.push_back({begin, begin + 100'000, 11'111 + (i % 6) * 2'778});
  }
  const PatternCalculator c = MakeWith(g, r);
  const Reference ref(Emu3(), g, r);
  const std::int64_t limit = kOrigin + 4'500'000;
  for (std::int64_t k = 0; k < 64; ++k) {
    const PositionEstimate pos{kOrigin + k * 60'000, 40'000, 40'000, 8'000 + (k * 997) % 15'000, false};
    const Evaluation e = c.Evaluate(pos, limit);
    ASSERT_EQ(e.status, EvalStatus::kOk);
    const std::int64_t xs = pos.front_mm + pos.front_error_mm;
    const std::int64_t ext = 60'000 + 80'000;
    const double re = ref.Speed(Pattern::kEmergency, xs, limit, ext);
    const double rn = ref.Speed(Pattern::kService, xs, limit, ext);
    EXPECT_LE(static_cast<double>(e.speeds.v_e), re + 1e-6) << k;
    EXPECT_LE(re - static_cast<double>(e.speeds.v_e), ref.GapBound(Pattern::kEmergency, re)) << k;
    EXPECT_LE(static_cast<double>(e.speeds.v_7n), rn + 1e-6) << k;
    EXPECT_LE(rn - static_cast<double>(e.speeds.v_7n), ref.GapBound(Pattern::kService, rn)) << k;
  }
  // full capacity
  std::vector<GradientSegment> g_full;
  std::vector<RestrictionSegment> r_full;
  for (std::int64_t i = 0; i < params::br::max_profile_entries; ++i) {
    g_full.push_back({kOrigin + i * 39'000, kOrigin + i * 39'000 + 30'000, (i % 9 - 4) * 60});
    r_full.push_back({kOrigin + i * 39'000, kOrigin + i * 39'000 + 20'000, 9'000 + (i % 4) * 4'000});
  }
  PatternCalculator full = Make();
  ASSERT_EQ(full.SetProfile(g_full, r_full).verdict, ProfileVerdict::kAccept);
  const Reference ref_full(Emu3(), g_full, r_full);
  for (std::int64_t y = kOrigin - 100'000; y < kOrigin + kLookAhead; y += 77'777) {
    const std::int64_t v = full.EmergencyPatternSpeed(y, kOrigin + kLookAhead, 1'000, 1'000);
    const double real = ref_full.Speed(Pattern::kEmergency, y, kOrigin + kLookAhead, 62'000);
    EXPECT_LE(static_cast<double>(v), real + 1e-6) << y;
    EXPECT_LE(real - static_cast<double>(v), ref_full.GapBound(Pattern::kEmergency, real)) << y;
  }
}

}  // namespace
}  // namespace railproof::br
