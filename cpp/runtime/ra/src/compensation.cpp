// Start-point search and the compensation candidates (spec/design/ra.md §7, §8):
// the IMU 6-axis compensation (pitch and roll initialisation, corrected pitch rate,
// trapezoidal integration of A_x on cycle means) and the speed/position bounds of the
// former max/min-acceleration method (baseline). The same per-cycle function serves the
// catch-up over the history at detection and the incremental advance afterwards, so both
// give bit-identical results.
//
// Seeded faults (negative tests, cpp/runtime/ra/tests/test_odometry.cpp kills each):
//   FAULT_RA_NO_GRAVITY_COMPENSATION   A_x = a_x (the G sin(theta) term left out)
//   FAULT_RA_NO_CANT_CORRECTION        omega_y'' without the yaw-in-cant term omega_z sin(Psi)
// Active only in the test-only schemata variant (spec/design/seeded-faults.md).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "railproof/core/seeded_fault.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/odometry.hpp"

namespace railproof::ra {
namespace {

namespace p = params::ra;

constexpr double kG = static_cast<double>(p::gravity_mm_s2) / 1000.0;  // m/s^2
constexpr double kDt = static_cast<double>(p::cycle_ms) / 1000.0;     // s
constexpr std::int64_t kLookback = p::lookback_ms / p::cycle_ms;      // L = 25
constexpr std::int64_t kSearchDepth = p::search_depth_ms / p::cycle_ms;  // 50
constexpr std::int64_t kConfirm = p::confirm_cycles;                  // 3

}  // namespace

// Start point for a detection at history index d (design note §7): the first k searched
// backwards from d - L down to d - L - depth at which the jerk conditions held for
// confirm_cycles consecutive cycles k-2..k; otherwise the oldest allowed point. The search
// is limited to the history held with full averaging windows (after a start or a rejected
// cycle the history is shorter: then the oldest usable cycle is the fallback).
// @implements REQ-RA-004
std::int64_t Odometry::StartPoint(std::int64_t d) const noexcept {
  // the oldest usable point: held in the ring, with full averaging windows
  const std::int64_t oldest = OldestUsable();
  const std::int64_t fallback = std::max(d - kLookback - kSearchDepth, oldest);
  const std::int64_t lowest_k = std::max(d - kLookback - kSearchDepth, oldest + kConfirm - 1);
  for (std::int64_t k = d - kLookback; k >= lowest_k; --k) {
    bool held = true;
    for (std::int64_t j = k - kConfirm + 1; j <= k; ++j) held = held && At(j).jerk_ok;
    if (held) return k;
  }
  return fallback;
}

// @implements REQ-RA-005 REQ-RA-014
void Odometry::InitCandidate(CandidateState& c, std::int64_t start, bool slip) const noexcept {
  const HistoryEntry& e = At(start);
  c = CandidateState{};
  c.active = true;
  c.start = start;
  c.cycles = 0;
  // v0 = v_TG(s) (design note §7), or the compensated speed where a compensation replaced
  // the TG values. v_TG is the mean over its measuring interval (tg_lag_s old): the delay
  // is not taken out for the IMU method, because under traction and braking it largely
  // cancels the wheel creep's bias (the odometry study's scenario suite: worst error/bound
  // ratio 0.79 without, 0.94 with the correction). The baseline's speed bounds span both.
  const double v0 = e.v_tg;
  const double v0_delay = e.comp ? e.v_tg : e.v_tg + e.ap * e.tg_lag_s;
  c.v = v0;
  c.d = 0.0;
  c.base_um = static_cast<double>(e.front_um);
  c.base_d = 0.0;
  c.slip = slip;
  if (cfg_.method == Method::kImu) {
    // theta0 = arcsin((a_x - A_p)/G), Psi0 = arctan((a_y - v0 w_z)/a_z) at the start point;
    // in a cycle whose TG values a compensation replaced, its speed and pitch.
    if (e.comp) {
      c.theta = e.theta_comp;
    } else {
      const double s = std::clamp((e.ax_avg - e.ap) / kG, -1.0, 1.0);
      c.theta = std::asin(s);
    }
    c.psi = std::fabs(e.az) > 1e-9 ? std::atan((e.ay - v0 * e.wz) / e.az) : 0.0;
    c.ax_prev = RAILPROOF_FAULT(FAULT_RA_NO_GRAVITY_COMPENSATION) ? e.ax : e.ax - kG * std::sin(c.theta);
  } else {
    // Baseline (design note §8, D1 §3.4.3): a slip advances the front with the maximum
    // acceleration and the rear with the minimum acceleration including coasting (coasting);
    // a slide the front with the least deceleration including coasting (coasting) and the
    // rear with the maximum deceleration; the gravity component of the steepest gradient on
    // top (falling for the front, rising for the rear).
    BaselineAccelerations(c, slip);
    c.v_hi = std::max({v0, v0_delay, 0.0});
    c.v_lo = std::max(std::min(v0, v0_delay), 0.0);
    c.x_hi_um = c.x_lo_um = c.base_um;
  }
}

// The former method's acceleration bounds of a candidate (design note §8, D1 §3.4.3).
// @implements REQ-RA-014
void Odometry::BaselineAccelerations(CandidateState& c, bool slip) const noexcept {
  const double grade = kG * static_cast<double>(episode_gradient_x10_) / 10'000.0;
  if (slip) {
    c.a_front = static_cast<double>(cfg_.accel_max_mm_s2) / 1000.0 + grade;
    c.a_rear = -grade;  // coasting: the minimum acceleration including coasting
  } else {
    c.a_front = grade;  // coasting: the least deceleration including coasting
    c.a_rear = -(static_cast<double>(cfg_.decel_max_mm_s2) / 1000.0 + grade);
  }
}

// One cycle of a candidate on the cycle means of history entry e (design note §7).
// @implements REQ-RA-005 REQ-RA-014
void Odometry::AdvanceCandidate(CandidateState& c, const HistoryEntry& e) const noexcept {
  c.cycles += 1;
  if (cfg_.method == Method::kImu) {
    // omega_y'' = omega_y + omega_z sin(Psi) - |omega_x| sin(theta)
    const double cant = RAILPROOF_FAULT(FAULT_RA_NO_CANT_CORRECTION) ? 0.0 : e.wz * std::sin(c.psi);
    const double wy2 = e.wy + cant - std::fabs(e.wx) * std::sin(c.theta);
    c.theta += wy2 * kDt;
    c.psi += e.wx * kDt;
    const double ax = RAILPROOF_FAULT(FAULT_RA_NO_GRAVITY_COMPENSATION) ? e.ax : e.ax - kG * std::sin(c.theta);
    const double v1 = c.v + 0.5 * (c.ax_prev + ax) * kDt;  // trapezoidal rule
    c.d += 0.5 * (c.v + v1) * kDt;
    c.v = v1;
    c.ax_prev = ax;
  } else {
    // the episode's steepest gradient only grows, so the bounds only widen
    BaselineAccelerations(c, c.slip);
    const double hi1 = c.v_hi + c.a_front * kDt;
    c.x_hi_um += 0.5 * (c.v_hi + hi1) * kDt * 1e6;
    c.v_hi = hi1;
    const double lo1 = c.v_lo + c.a_rear * kDt;
    if (lo1 >= 0.0) {
      c.x_lo_um += 0.5 * (c.v_lo + lo1) * kDt * 1e6;
      c.v_lo = lo1;
    } else {
      c.x_lo_um += c.v_lo * c.v_lo / (2.0 * -c.a_rear) * 1e6;  // stops within the cycle
      c.v_lo = 0.0;
    }
  }
  if (e.balise) {
    // A balise fix resets the position base, not the compensation (design note §5 step 5).
    c.base_um = static_cast<double>(e.balise_um);
    c.base_d = c.d;
    c.x_hi_um = c.x_lo_um = c.base_um;
  }
}

// The candidate's state at history entry e (IMU method).
void Odometry::Record(std::size_t c, HistoryEntry& e) const noexcept {
  const CandidateState& k = cand_[c];
  e.cand_v[c] = k.v;
  e.cand_theta[c] = k.theta;
  e.cand_x_um[c] = CandidateFrontUm(k);
}

// The compensation replaces the TG values from its start point to history entry `last`
// (design note §7: the compensated distance replaces the TG distance), so that later
// averages (A_p) and start points use the compensated speed, position and pitch and not
// the slipping TG's. Bounded by the candidate's age (<= history_cycles).
// @implements REQ-RA-005
//
// The replaced speeds are blended linearly from the compensated speed at the start point to
// the measured TG speed at `last`: the re-adhesion judgement accepts a difference of up to
// readhesion_rate x t between them, and a step of that size in the history would come back
// 3 s later as a TG acceleration (A_p) of up to 0.17 m/s^2 and raise a spurious deviation
// (seen at standstill after a slide on -35 permille: repeated detections every 3.3 s).
void Odometry::ReplaceTg(std::size_t c, std::int64_t last) noexcept {
  const std::int64_t first = std::max(cand_[c].start + 1, Oldest());
  const double step = At(last).v_tg - At(last).cand_v[c];
  const double span = static_cast<double>(std::max<std::int64_t>(last - cand_[c].start, 1));
  for (std::int64_t j = first; j <= last; ++j) {
    HistoryEntry& e = At(j);
    e.v_tg = e.cand_v[c] + step * (static_cast<double>(j - cand_[c].start) / span);
    e.front_um = std::llround(e.cand_x_um[c]);
    e.theta_comp = e.cand_theta[c];
    e.comp = true;
    e.jerk_ok = false;
  }
}

// x_c = x(start) + d_c, re-based at a balise fix.
// @implements REQ-RA-005
double Odometry::CandidateFrontUm(const CandidateState& c) const noexcept {
  return c.base_um + (c.d - c.base_d) * 1e6;
}

double Odometry::CandidateSpeed(const CandidateState& c) const noexcept {
  return cfg_.method == Method::kImu ? c.v : c.v_hi;
}

}  // namespace railproof::ra
