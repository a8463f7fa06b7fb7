// Offline design calculator of the two-counter digital speed check (D3, digest §5;
// spec/design/br.md §6; REQ-SC-002, REQ-SC-004, REQ-SC-005, REQ-SC-006). Normal C++
// (doubles, may allocate, throws std::invalid_argument on bad input); not runtime.
//
// Units: speeds km/h, alpha km/h/s, times s, frequencies Hz (as in D3); the runtime-facing
// functions (SpeedErrorBoundMmS, AllowanceCovers) use mm/s. Timing terms per ASM-023:
// T_c'' = tc_over_ts * T_s, T_s'' = ts2_over_ts * T_s (both 1 by default), so the timing
// factor K = T_c''/(2 T_s) + T_s''/T_s = 1.5.
//
//   static error        dV_s = V_E / n_1F
//   sampling time       T_s  = n_1F / f_1
//   dynamic error       dV_d = dV_1 + (sqrt(1 + 2 alpha T_s'' V_E' / V_F^2) - 1) V_F,
//                       V_E' = V_E + dV_s, dV_1 = alpha T_c'' / 2, V_F = V_E' + dV_1
//                       (the gate covers a fixed distance; T_s' of D3 taken = T_s'')
//   total (D3)          dV   = V_E / n_1F + alpha T_s K   (>= dV_s + dV_d: sqrt(1+x)-1 <= x/2
//                                                          and V_E' <= V_F)
//   design curve        f_1(n_1F) = (K alpha n_1F^2 / V_E) / (r n_1F - 1), r = dV / V_E
//                       (solve dV = V_E/n + alpha K n / f for f)
//   minimum             n_1F = 2 / r,  f_M = 4 K alpha / V_E / r^2; there T_s = r V_E/(2 alpha K)
//                       and dV = 2 V_E / n_1F (the two error parts are equal), for any alpha
//   asymptote           n_1F = 1 / r (the static error alone uses up the target)
//   TG                  f_2E = V_E / (pi D) * teeth (V_E in m/s); n_2E = floor(f_2E T_s):
//                       at the check speed the gate n_2E / f_2E <= T_s, so counter 1 reaches at
//                       most n_1F there and the check brakes at the check speed; the brake
//                       threshold is V_th = V_E n_2E / (f_2E T_s) <= V_E (rounding to the safe
//                       side). Constraint (REQ-SC-006): f_1 <= f_2E n_1F / n_2E, which with
//                       the floor holds whenever f_2E T_s >= 1 (at least one TG pulse per gate).
//
// Target basis: D3 states the target as "<= 0.25 % (0.625 km/h)", i.e. a fraction of the
// design's maximum speed V_E max. With a sampling time common to all check speeds the
// dynamic error alpha T_s K is the same number of km/h at every check speed, so a fraction
// of each (low) check speed cannot be met (at 5 km/h the dynamic error alone is several
// per cent). TargetBasis selects the reading; every row reports both percentages.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "railproof/br/speed_check.hpp"

namespace railproof::br::analysis {

enum class TargetBasis : std::uint8_t {
  kDesignMaxSpeed,  // target = target_ratio * max_speed_kmh at every check speed (D3 reading)
  kCheckSpeed,      // target = target_ratio * check speed
};

const char* ToString(TargetBasis b) noexcept;

struct SpeedCheckInputs {
  double max_speed_kmh = 0.0;        // V_E max of the design (the highest check speed)
  double alpha_kmh_s = 0.0;          // constant acceleration alpha (km/h/s)
  double target_ratio = 0.0;         // target total error dV / V_E (e.g. 0.0025)
  TargetBasis target_basis = TargetBasis::kDesignMaxSpeed;
  double tc_over_ts = 1.0;           // T_c'' / T_s (ASM-023)
  double ts2_over_ts = 1.0;          // T_s'' / T_s (ASM-023)
  std::vector<double> check_speeds_kmh;  // D3: 250, 210, 160, 110, 70, 30, 5
  double tg_teeth = 0.0;             // TG pulses per wheel revolution
  double wheel_diameter_mm = 0.0;
  double reference_sampling_s = 0.0; // D3's sampling period (0.312 s), for the comparison
};

// The reference inputs from spec/parameters/sc.yaml (generated constants).
SpeedCheckInputs ReferenceSpeedCheckInputs();

// Throws std::invalid_argument naming the first invalid field.
void Validate(const SpeedCheckInputs& in);

// K = T_c''/(2 T_s) + T_s''/T_s.
double TimingFactor(const SpeedCheckInputs& in);

// @implements REQ-SC-004
double StaticErrorKmh(double v_e_kmh, double n_1f);
// @implements REQ-SC-004
double SamplingTimeS(double n_1f, double f_1_hz);
// Dynamic error (exact D3 form) at check speed v_e_kmh.
// @implements REQ-SC-004
double DynamicErrorKmh(const SpeedCheckInputs& in, double v_e_kmh, double n_1f, double f_1_hz);
// Total error (D3): V_E / n_1F + alpha T_s K.
// @implements REQ-SC-004
double TotalErrorKmh(const SpeedCheckInputs& in, double v_e_kmh, double n_1f, double f_1_hz);

// Design curve f_1(n_1F) at the target (+infinity at or left of the asymptote).
// @implements REQ-SC-004
double DesignCurveF1Hz(const SpeedCheckInputs& in, double n_1f);
double OptimumN1F(const SpeedCheckInputs& in);      // 2 / r
double MinimumF1Hz(const SpeedCheckInputs& in);     // f_M
double AsymptoteN1F(const SpeedCheckInputs& in);    // 1 / r
// Points (n_1F, f_1) of the design curve for n_1F in (asymptote, n_to], `points` of them,
// denser near the asymptote.
std::vector<std::pair<double, double>> DesignCurve(const SpeedCheckInputs& in, double n_to,
                                                   int points);

// TG pulse frequency at speed v_kmh (Hz).
// @implements REQ-SC-006
double TgFrequencyHz(const SpeedCheckInputs& in, double v_kmh);

// One check speed of a design.
struct CheckSpeedRow {
  double check_speed_kmh = 0.0;
  double f_2e_hz = 0.0;             // TG frequency at the check speed
  std::int64_t n_2e = 0;            // floor(f_2E T_s), at least 1
  double gate_s = 0.0;              // n_2E / f_2E (<= T_s)
  double threshold_kmh = 0.0;       // V_E n_2E / (f_2E T_s): speed from which it always brakes
  double static_kmh = 0.0;
  double dynamic_kmh = 0.0;         // exact D3 form
  double dynamic_linear_kmh = 0.0;  // alpha T_s K (the part of the total)
  double total_kmh = 0.0;           // D3 total
  double total_pct_of_check = 0.0;  // 100 * total / check speed
  double total_pct_of_max = 0.0;    // 100 * total / max_speed_kmh
  double target_kmh = 0.0;          // per target_basis
  bool meets_target = false;        // total <= target (relative tolerance 1e-9)
  double tg_limit_hz = 0.0;         // f_2E n_1F / n_2E
  bool tg_ok = false;               // f_1 <= tg_limit (and f_2E T_s >= 1)
};

struct SpeedCheckDesign {
  SpeedCheckInputs inputs;
  std::int64_t n_1f = 0;
  double f_1_hz = 0.0;
  double sampling_s = 0.0;  // n_1F / f_1
  std::vector<CheckSpeedRow> rows;

  [[nodiscard]] bool MeetsTarget() const;  // every row
  [[nodiscard]] bool TgOk() const;         // every row
};

// A design with the given n_1F and f_1: rows for every check speed.
// @implements REQ-SC-002 REQ-SC-004 REQ-SC-006
SpeedCheckDesign MakeSpeedCheckDesign(const SpeedCheckInputs& in, std::int64_t n_1f,
                                      double f_1_hz);

// D3 design rule: n_1F = 2 / r (rounded to the nearest integer), f_1 = the design curve
// there rounded up to a whole Hz (= f_M when 2 / r is an integer).
// @implements REQ-SC-004
SpeedCheckDesign OptimumSpeedCheckDesign(const SpeedCheckInputs& in);

// The smallest n_1F that meets the target at V_E max with the sampling time fixed to
// sampling_s (f_1 = n_1F / sampling_s rounded up to a whole Hz). Throws if alpha T_s K alone
// reaches the target.
SpeedCheckDesign FixedSamplingSpeedCheckDesign(const SpeedCheckInputs& in, double sampling_s);

// Total speed-error bound of a measurement at true_speed_mm_s (>= 0), mm/s rounded up:
// true_speed / n_1F (the static part, the speed taken as the check speed) plus
// alpha T_s K (dynamic part). The margin verification uses it as the speed-error
// uncertainty (REQ-SC-005). Throws on a negative speed.
// @implements REQ-SC-005
std::int64_t SpeedErrorBoundMmS(const SpeedCheckDesign& design, std::int64_t true_speed_mm_s);

struct AllowanceCheck {
  // max over true speeds v in [0, v_max] of bound(v) - allowance(v_m), with the lowest
  // measured speed v_m = max(0, v - bound(v)) and allowance(v_m) =
  // ceil(v_m * ppm / 1e6) + abs (spec/design/br.md §2). <= 0: covered.
  std::int64_t worst_shortfall_mm_s = 0;
  std::int64_t at_speed_mm_s = 0;  // the true speed of the worst case (lowest if tied)
  [[nodiscard]] bool Covered() const { return worst_shortfall_mm_s <= 0; }
};

// REQ-SC-005: does the supervision's allowance cover the design's error bound at every
// integer speed 0..v_max_mm_s? Throws on negative arguments.
// @implements REQ-SC-005
AllowanceCheck AllowanceCovers(const SpeedCheckDesign& design, std::int64_t speed_error_ppm,
                               std::int64_t speed_error_abs_mm_s, std::int64_t v_max_mm_s);

// Runtime configuration of br::TwoCounterSpeedCheck from a design (f_1 rounded up
// to a whole Hz, check speeds rounded to whole km/h). The table entries are stored in
// `table` (which must outlive the returned config's span).
br::SpeedCheckConfig ToRuntimeConfig(const SpeedCheckDesign& design,
                                          std::int64_t gate_timeout_ms,
                                          std::int64_t oscillator_timeout_ms,
                                          std::vector<br::CheckSpeedEntry>& table);

// km/h -> mm/s, rounded up.
std::int64_t KmhToMmSCeil(double kmh);

}  // namespace railproof::br::analysis
