// Offline design calculator of the two-counter digital speed check (D3, digest §5). The
// formulas and their derivation are in the header.
#include "railproof/br/analysis/speedcheck_design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "railproof/generated/sc_params.hpp"

namespace railproof::br::analysis {

namespace {

namespace sc = params::sc;

// Relative tolerance of the target comparisons: the optimum design meets its design point
// with equality (dV = 2 V_E / n_1F = r_d V_E), which doubles reproduce only to ~1e-16.
constexpr double kTargetTolerance = 1e-9;

// km/h/s -> mm/s^2 and km/h -> mm/s: * 1e6 / 3600 = * 2500 / 9.
constexpr double kKmhToMmS = 2500.0 / 9.0;

void Require(bool ok, const std::string& what) {
  if (!ok) {
    throw std::invalid_argument("speed-check design: " + what);
  }
}

// The speed the target and the margin are a fraction of (TargetBasis).
double BasisKmh(const SpeedCheckInputs& in, double check_speed_kmh) {
  return in.target_basis == TargetBasis::kCheckSpeed ? check_speed_kmh : in.max_speed_kmh;
}

}  // namespace

const char* ToString(TargetBasis b) noexcept {
  switch (b) {
    case TargetBasis::kDesignMaxSpeed: return "design_max_speed";
    case TargetBasis::kCheckSpeed: return "check_speed";
  }
  return "invalid";
}

SpeedCheckInputs ReferenceSpeedCheckInputs() {
  SpeedCheckInputs in;
  in.max_speed_kmh = static_cast<double>(sc::design_max_speed_kmh);
  in.alpha_kmh_s = static_cast<double>(sc::design_accel_kmh_s_x1000) / 1000.0;
  in.target_ratio = static_cast<double>(sc::design_total_error_ppm) / 1e6;
  in.margin_ratio = static_cast<double>(sc::design_margin_ppm) / 1e6;
  in.target_basis = TargetBasis::kDesignMaxSpeed;
  in.tc_over_ts = 1.0;   // ASM-023
  in.ts2_over_ts = 1.0;  // ASM-023
  const std::int64_t speeds[] = {sc::check_speed_1_kmh, sc::check_speed_2_kmh,
                                 sc::check_speed_3_kmh, sc::check_speed_4_kmh,
                                 sc::check_speed_5_kmh, sc::check_speed_6_kmh,
                                 sc::check_speed_7_kmh};
  static_assert(sc::check_speeds_count == 7, "update the check-speed list");
  for (const std::int64_t v : speeds) {
    in.check_speeds_kmh.push_back(static_cast<double>(v));
  }
  in.tg_teeth = static_cast<double>(sc::tg_teeth);
  in.wheel_diameter_mm = static_cast<double>(sc::wheel_diameter_mm);
  in.reference_sampling_s = static_cast<double>(sc::design_sampling_ms_x1000) / 1e6;
  return in;
}

void Validate(const SpeedCheckInputs& in) {
  Require(std::isfinite(in.max_speed_kmh) && in.max_speed_kmh > 0.0,
          "max_speed_kmh must be positive");
  Require(std::isfinite(in.alpha_kmh_s) && in.alpha_kmh_s > 0.0, "alpha_kmh_s must be positive");
  Require(std::isfinite(in.target_ratio) && in.target_ratio > 0.0 && in.target_ratio < 0.5,
          "target_ratio must be in (0, 0.5)");
  Require(std::isfinite(in.margin_ratio) && in.margin_ratio >= 0.0 &&
              in.margin_ratio < in.target_ratio,
          "margin_ratio must be in [0, target_ratio)");
  Require(std::isfinite(in.tc_over_ts) && in.tc_over_ts >= 0.0, "tc_over_ts must be >= 0");
  Require(std::isfinite(in.ts2_over_ts) && in.ts2_over_ts >= 0.0, "ts2_over_ts must be >= 0");
  Require(in.tc_over_ts + in.ts2_over_ts > 0.0, "the timing factor must be positive");
  Require(!in.check_speeds_kmh.empty(), "no check speed");
  for (const double v : in.check_speeds_kmh) {
    Require(std::isfinite(v) && v > 0.0 && v <= in.max_speed_kmh,
            "check speed " + std::to_string(v) + " km/h not in (0, max_speed_kmh]");
  }
  Require(std::isfinite(in.tg_teeth) && in.tg_teeth > 0.0, "tg_teeth must be positive");
  Require(std::isfinite(in.wheel_diameter_mm) && in.wheel_diameter_mm > 0.0,
          "wheel_diameter_mm must be positive");
  Require(std::isfinite(in.reference_sampling_s) && in.reference_sampling_s >= 0.0,
          "reference_sampling_s must be >= 0");
}

double TimingFactor(const SpeedCheckInputs& in) { return in.tc_over_ts / 2.0 + in.ts2_over_ts; }

double DesignRatio(const SpeedCheckInputs& in) { return in.target_ratio - in.margin_ratio; }

double TargetKmh(const SpeedCheckInputs& in, double check_speed_kmh) {
  return in.target_ratio * BasisKmh(in, check_speed_kmh);
}

double MarginKmh(const SpeedCheckInputs& in, double check_speed_kmh) {
  return in.margin_ratio * BasisKmh(in, check_speed_kmh);
}

// @implements REQ-SC-004
double StaticErrorKmh(double v_e_kmh, double n_1f) {
  Require(n_1f >= 1.0, "n_1F must be >= 1");
  return v_e_kmh / n_1f;
}

// @implements REQ-SC-004
double SamplingTimeS(double n_1f, double f_1_hz) {
  Require(f_1_hz > 0.0, "f_1 must be positive");
  return n_1f / f_1_hz;
}

// @implements REQ-SC-004
double DynamicErrorKmh(const SpeedCheckInputs& in, double v_e_kmh, double n_1f, double f_1_hz,
                       SpeedChange change) {
  const double t_s = SamplingTimeS(n_1f, f_1_hz);
  const double t_c2 = in.tc_over_ts * t_s;
  const double t_s2 = in.ts2_over_ts * t_s;
  // D3's form with a signed acceleration: V_E' = V_E + sign dV_s, V_F = V_E' + sign dV_1
  const double sign = change == SpeedChange::kAccelerating ? 1.0 : -1.0;
  const double v_e1 = v_e_kmh + sign * StaticErrorKmh(v_e_kmh, n_1f);  // V_E'
  const double dv_1 = in.alpha_kmh_s * t_c2 / 2.0;
  const double v_f = v_e1 + sign * dv_1;
  const double arg = v_f > 0.0 ? 1.0 + sign * 2.0 * in.alpha_kmh_s * t_s2 * v_e1 / (v_f * v_f) : -1.0;
  if (arg < 0.0) {
    return std::max(v_e1, 0.0);  // decelerating: the train stops within the last sample
  }
  return dv_1 + sign * (std::sqrt(arg) - 1.0) * v_f;
}

// @implements REQ-SC-004
double TotalErrorKmh(const SpeedCheckInputs& in, double v_e_kmh, double n_1f, double f_1_hz) {
  return StaticErrorKmh(v_e_kmh, n_1f) +
         in.alpha_kmh_s * SamplingTimeS(n_1f, f_1_hz) * TimingFactor(in);
}

// @implements REQ-SC-004
double DesignCurveF1Hz(const SpeedCheckInputs& in, double ratio, double n_1f) {
  const double denom = ratio * n_1f - 1.0;
  if (denom <= 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  return (TimingFactor(in) * in.alpha_kmh_s * n_1f * n_1f / in.max_speed_kmh) / denom;
}

double OptimumN1F(double ratio) { return 2.0 / ratio; }

double MinimumF1Hz(const SpeedCheckInputs& in, double ratio) {
  return 4.0 * TimingFactor(in) * in.alpha_kmh_s / in.max_speed_kmh / (ratio * ratio);
}

double AsymptoteN1F(double ratio) { return 1.0 / ratio; }

std::vector<std::pair<double, double>> DesignCurve(const SpeedCheckInputs& in, double ratio,
                                                   double n_to, int points) {
  Validate(in);
  Require(std::isfinite(ratio) && ratio > 0.0, "the curve's error ratio must be positive");
  const double n_a = AsymptoteN1F(ratio);
  Require(n_to > n_a, "the curve must extend beyond the asymptote");
  Require(points >= 2, "at least two curve points");
  // (n - n_a) log-spaced from n_a / 50 to n_to - n_a.
  const double lo = std::log(n_a / 50.0);
  const double hi = std::log(n_to - n_a);
  std::vector<std::pair<double, double>> out;
  out.reserve(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) {
    const double n = n_a + std::exp(lo + (hi - lo) * i / (points - 1));
    out.emplace_back(n, DesignCurveF1Hz(in, ratio, n));
  }
  return out;
}

// @implements REQ-SC-006
double TgFrequencyHz(const SpeedCheckInputs& in, double v_kmh) {
  const double v_mm_s = v_kmh * kKmhToMmS;
  return v_mm_s / (std::numbers::pi * in.wheel_diameter_mm) * in.tg_teeth;
}

bool SpeedCheckDesign::MeetsTarget() const {
  return std::all_of(rows.begin(), rows.end(), [](const CheckSpeedRow& r) { return r.meets_target; });
}

bool SpeedCheckDesign::WithinRequirement() const {
  return std::all_of(rows.begin(), rows.end(),
                     [](const CheckSpeedRow& r) { return r.within_requirement; });
}

bool SpeedCheckDesign::TgOk() const {
  return std::all_of(rows.begin(), rows.end(), [](const CheckSpeedRow& r) { return r.tg_ok; });
}

double SpeedCheckDesign::MinMarginKmh() const {
  double m = std::numeric_limits<double>::infinity();
  for (const CheckSpeedRow& r : rows) {
    m = std::min(m, r.margin_kmh);
  }
  return m;
}

// @implements REQ-SC-002 REQ-SC-004 REQ-SC-006
SpeedCheckDesign MakeSpeedCheckDesign(const SpeedCheckInputs& in, std::int64_t n_1f,
                                      double f_1_hz) {
  Validate(in);
  Require(n_1f >= 1, "n_1F must be >= 1");
  Require(std::isfinite(f_1_hz) && f_1_hz > 0.0, "f_1 must be positive");
  SpeedCheckDesign d;
  d.inputs = in;
  d.n_1f = n_1f;
  d.f_1_hz = f_1_hz;
  const auto n = static_cast<double>(n_1f);
  d.sampling_s = SamplingTimeS(n, f_1_hz);
  for (const double v : in.check_speeds_kmh) {
    CheckSpeedRow r;
    r.check_speed_kmh = v;
    r.f_2e_hz = TgFrequencyHz(in, v);
    const double pulses = r.f_2e_hz * d.sampling_s;  // f_2E T_s
    r.n_2e = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor(pulses)));
    r.gate_s = static_cast<double>(r.n_2e) / r.f_2e_hz;
    r.threshold_kmh = v * static_cast<double>(r.n_2e) / pulses;
    r.static_kmh = StaticErrorKmh(v, n);
    r.dynamic_kmh = DynamicErrorKmh(in, v, n, f_1_hz);
    r.dynamic_decel_kmh = DynamicErrorKmh(in, r.threshold_kmh, n, f_1_hz, SpeedChange::kDecelerating);
    r.release_error_kmh = StaticErrorKmh(r.threshold_kmh, n) + r.dynamic_decel_kmh;
    r.dynamic_linear_kmh = in.alpha_kmh_s * d.sampling_s * TimingFactor(in);
    r.total_kmh = TotalErrorKmh(in, v, n, f_1_hz);
    r.total_pct_of_check = 100.0 * r.total_kmh / v;
    r.total_pct_of_max = 100.0 * r.total_kmh / in.max_speed_kmh;
    r.target_kmh = TargetKmh(in, v);
    r.required_margin_kmh = MarginKmh(in, v);
    r.margin_kmh = r.target_kmh - r.total_kmh;
    r.within_requirement = r.total_kmh <= r.target_kmh * (1.0 + kTargetTolerance);
    // margin >= required  <=>  total <= target - required (the design point)
    r.meets_target = r.total_kmh <= (r.target_kmh - r.required_margin_kmh) * (1.0 + kTargetTolerance);
    r.tg_limit_hz = r.f_2e_hz * n / static_cast<double>(r.n_2e);
    r.tg_ok = f_1_hz <= r.tg_limit_hz * (1.0 + 1e-12);
    d.rows.push_back(r);
  }
  return d;
}

// @implements REQ-SC-004
SpeedCheckDesign OptimumSpeedCheckDesign(const SpeedCheckInputs& in) {
  Validate(in);
  const double r_d = DesignRatio(in);
  const std::int64_t n = std::llround(OptimumN1F(r_d));
  const double f = DesignCurveF1Hz(in, r_d, static_cast<double>(n));
  Require(std::isfinite(f), "no design at the optimum");
  // Whole Hz, rounded up (a higher f_1 lowers the error); the relative slack keeps an
  // exact f_M (6000 Hz for the reference) from becoming f_M + 1 by a rounding error.
  const double f_1 = std::ceil(f * (1.0 - 1e-12));
  return MakeSpeedCheckDesign(in, n, f_1);
}

SpeedCheckDesign FixedSamplingSpeedCheckDesign(const SpeedCheckInputs& in, double sampling_s) {
  Validate(in);
  Require(std::isfinite(sampling_s) && sampling_s > 0.0, "sampling time must be positive");
  const double dynamic = in.alpha_kmh_s * sampling_s * TimingFactor(in);
  const double budget = DesignRatio(in) * in.max_speed_kmh - dynamic;
  Require(budget > 0.0, "the dynamic error alone reaches the design point at this sampling time");
  const auto n = static_cast<std::int64_t>(std::ceil(in.max_speed_kmh / budget * (1.0 - 1e-12)));
  const double f_1 = std::ceil(static_cast<double>(n) / sampling_s * (1.0 - 1e-12));
  return MakeSpeedCheckDesign(in, n, f_1);
}

// @implements REQ-SC-005
std::int64_t SpeedErrorBoundMmS(const SpeedCheckDesign& design, std::int64_t true_speed_mm_s) {
  Require(true_speed_mm_s >= 0, "speed must be >= 0");
  Require(design.n_1f >= 1 && design.sampling_s > 0.0, "design not initialised");
  const double stat = static_cast<double>(true_speed_mm_s) / static_cast<double>(design.n_1f);
  const double dyn = design.inputs.alpha_kmh_s * kKmhToMmS * design.sampling_s *
                     TimingFactor(design.inputs);
  const double reserve =
      MarginKmh(design.inputs, static_cast<double>(true_speed_mm_s) / kKmhToMmS) * kKmhToMmS;
  return static_cast<std::int64_t>(std::ceil(stat + dyn + reserve));
}

// @implements REQ-SC-005
AllowanceCheck AllowanceCovers(const SpeedCheckDesign& design, std::int64_t speed_error_ppm,
                               std::int64_t speed_error_abs_mm_s, std::int64_t v_max_mm_s) {
  Require(speed_error_ppm >= 0 && speed_error_abs_mm_s >= 0 && v_max_mm_s >= 0,
          "allowance and speed must be >= 0");
  AllowanceCheck worst;
  worst.worst_shortfall_mm_s = std::numeric_limits<std::int64_t>::min();
  for (std::int64_t v = 0; v <= v_max_mm_s; ++v) {
    const std::int64_t bound = SpeedErrorBoundMmS(design, v);
    const std::int64_t v_m = std::max<std::int64_t>(0, v - bound);
    const std::int64_t allowance =
        (v_m * speed_error_ppm + 999'999) / 1'000'000 + speed_error_abs_mm_s;
    const std::int64_t shortfall = bound - allowance;
    if (shortfall > worst.worst_shortfall_mm_s) {
      worst.worst_shortfall_mm_s = shortfall;
      worst.at_speed_mm_s = v;
    }
  }
  return worst;
}

br::SpeedCheckConfig ToRuntimeConfig(const SpeedCheckDesign& design,
                                          std::int64_t gate_timeout_ms,
                                          std::int64_t oscillator_timeout_ms,
                                          std::vector<br::CheckSpeedEntry>& table) {
  table.clear();
  for (const CheckSpeedRow& r : design.rows) {
    table.push_back({std::llround(r.check_speed_kmh), r.n_2e});
  }
  br::SpeedCheckConfig c;
  c.f_1_hz = static_cast<std::int64_t>(std::ceil(design.f_1_hz));
  c.n_1f = design.n_1f;
  c.gate_timeout_ms = gate_timeout_ms;
  c.oscillator_timeout_ms = oscillator_timeout_ms;
  c.table = table;
  return c;
}

std::int64_t KmhToMmSCeil(double kmh) {
  Require(std::isfinite(kmh) && kmh >= 0.0, "speed must be >= 0");
  return static_cast<std::int64_t>(std::ceil(kmh * 2500.0 / 9.0));  // exact for whole km/h
}

}  // namespace railproof::br::analysis
