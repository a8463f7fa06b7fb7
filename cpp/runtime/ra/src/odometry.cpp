// On-board odometry (spec/design/ra.md §2-§8): configuration check, sensor stream
// validation, TG speed and distance, the 3 s moving averages, the predicates of the
// re-adhesion state machine, the section limits under the train and the position envelope.
// The candidate numerics (start point, 6-axis compensation, baseline bounds) are in
// compensation.cpp, the error model in error_model.cpp.
//
// Per cycle the work is O(1) apart from bounded look-ups: the TG timing search (<= 10
// history cycles), the section look-up (binary search plus the sections under the train),
// and on the detection cycle the start-point search (<= 51 cycles) and each candidate's
// catch-up over its history (<= 100 cycles). The moving average of a_x is a running sum of
// integers (1e-9 m/s^2), so it is exact and does not drift.
//
// Seeded faults (negative tests, cpp/runtime/ra/tests/test_odometry.cpp kills each):
//   FAULT_RA_WINDOW_SPEED_ONLY     the TG speed always from the 1 s pulse count
//   FAULT_RA_NO_PERMANENT_MARGIN   the margin is added to the envelope only while compensating
// Active only in the test-only schemata variant (spec/design/seeded-faults.md).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/ra/odometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "railproof/generated/ra_params.hpp"

namespace railproof::ra {
namespace {

namespace p = params::ra;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDt = static_cast<double>(p::cycle_ms) / 1000.0;     // s
constexpr std::int64_t kCycleUs = p::cycle_ms * 1000;
constexpr std::int64_t kAvgCycles = p::moving_average_ms / p::cycle_ms;   // 30
constexpr std::int64_t kWindowCycles = p::tg_window_ms / p::cycle_ms;     // 10
constexpr std::int64_t kMaxAbsTimeMs = 1'000'000'000'000;                 // ~31 years
constexpr std::int64_t kMaxPulses = 1'000'000'000'000'000;                // 3e13 m of 30 mm pulses
constexpr double kMaxAccel = static_cast<double>(p::imu_max_accel_mm_s2) / 1000.0;  // m/s^2
constexpr double kMaxRate = static_cast<double>(p::imu_max_rate_mrad_s) / 1000.0;   // rad/s
constexpr double kLowSpeed = static_cast<double>(p::low_speed_mm_s) / 1000.0;       // m/s

static_assert(p::moving_average_ms % p::cycle_ms == 0 && p::tg_window_ms % p::cycle_ms == 0);
static_assert(p::history_cycles >= (p::lookback_ms + p::search_depth_ms + p::parallel_spacing_ms) / p::cycle_ms + 3,
              "history too short for the start-point search and the second start point");

// The state machine of an odometry configuration: the warm-up at standstill fills the
// moving averages and the TG window (REQ-RA-015), the history the detection compares.
MachineConfig MachineConfigOf(const OdometryConfig& cfg) noexcept {
  return MachineConfig{static_cast<std::uint8_t>(p::confirm_cycles), cfg.start_points,
                       static_cast<std::int32_t>(p::parallel_spacing_ms / p::cycle_ms),
                       static_cast<std::int32_t>(kAvgCycles + kWindowCycles)};
}

// ceil(a / b) for a >= 0, b > 0.
constexpr std::int64_t CeilDiv(std::int64_t a, std::int64_t b) noexcept { return (a + b - 1) / b; }

// Nearest integer of a / b for b > 0 (halves away from -inf), without overflow for |a| < 9e18 - b.
constexpr std::int64_t RoundDiv(std::int64_t a, std::int64_t b) noexcept {
  const std::int64_t shifted = a + b / 2;
  const std::int64_t q = shifted / b;
  return (shifted % b != 0 && shifted < 0) ? q - 1 : q;
}

// mm (rounded up) of a non-negative length in um given as double.
std::int64_t CeilUmToMm(double um) noexcept {
  if (!(um > 0.0)) return 0;
  return static_cast<std::int64_t>(std::min(std::ceil(um / 1000.0), 1e15));
}

bool InRange(std::int64_t v, std::int64_t lo, std::int64_t hi) noexcept { return v >= lo && v <= hi; }

}  // namespace

Odometry::Odometry() noexcept {
  out_.position_valid = false;
  out_.stop_demand = true;
  out_.mode = Mode::kStopped;
}

// ---- configuration -----------------------------------------------------------------------

// @implements REQ-RA-007 REQ-RA-009
ConfigError Odometry::Create(const OdometryConfig& cfg, Odometry& out) noexcept {
  if (!InRange(cfg.wheel_diameter_um, 500'000, 1'500'000)) return ConfigError::kWheelDiameter;
  if (!InRange(cfg.train_length_mm, 1'000, 1'000'000)) return ConfigError::kTrainLength;
  if (!InRange(cfg.detect_threshold_mm_s2, 50, 2'000)) return ConfigError::kThreshold;
  if (cfg.start_points < 1 || cfg.start_points > kMaxStartPoints) return ConfigError::kStartPoints;
  if (!InRange(cfg.imu_rate_error_udeg_s, 0, 1'000'000)) return ConfigError::kRateError;
  if (!InRange(cfg.length_correction_ppm, 0, 100'000)) return ConfigError::kLengthCorrection;
  if (cfg.sections == nullptr || cfg.section_count < 1 || cfg.section_count > kMaxSections) {
    return ConfigError::kSectionCount;
  }
  for (int i = 0; i < cfg.section_count; ++i) {
    const OdometrySection& s = cfg.sections[i];
    if (s.begin_mm >= s.end_mm || !InRange(s.begin_mm, -kMaxAbsTimeMs * 10, kMaxAbsTimeMs * 10) ||
        !InRange(s.end_mm, -kMaxAbsTimeMs * 10, kMaxAbsTimeMs * 10)) {
      return ConfigError::kSectionOrder;
    }
    if (i > 0 && s.begin_mm != cfg.sections[i - 1].end_mm) return ConfigError::kSectionOrder;
    if (!InRange(s.gradient_permille_x10, 0, 1'000)) return ConfigError::kSectionGradient;
    if (!InRange(s.max_compensation_ms, p::min_compensation_ms, p::max_compensation_limit_ms) ||
        s.max_compensation_ms % p::cycle_ms != 0) {
      return ConfigError::kSectionTime;
    }
    if (s.margin_mm < 0 ||
        (s.margin_mm > 0 &&
         s.margin_mm < ErrorBoundMm(s.max_compensation_ms, s.gradient_permille_x10, cfg.imu_rate_error_udeg_s))) {
      return ConfigError::kSectionMargin;
    }
  }
  if (cfg.method == Method::kMaxMinAcceleration &&
      (!InRange(cfg.accel_max_mm_s2, 1, 10'000) || !InRange(cfg.decel_max_mm_s2, 1, 10'000))) {
    return ConfigError::kAccelBounds;
  }
  if (cfg.initial_front_mm < cfg.sections[0].begin_mm ||
      cfg.initial_front_mm >= cfg.sections[cfg.section_count - 1].end_mm) {
    return ConfigError::kInitialOutside;
  }
  if (ReadhesionMachine::Validate(MachineConfigOf(cfg)) != MachineError::kNone) return ConfigError::kStartPoints;
  out.Init(cfg);
  return ConfigError::kNone;
}

void Odometry::Init(const OdometryConfig& cfg) noexcept {
  created_ = true;
  cfg_ = cfg;
  cfg_.sections = nullptr;
  section_count_ = cfg.section_count;
  for (int i = 0; i < kMaxSections; ++i) {
    SectionEntry e{};
    if (i < cfg.section_count) {
      const OdometrySection& s = cfg.sections[i];
      e.begin_mm = s.begin_mm;
      e.end_mm = s.end_mm;
      e.gradient_x10 = s.gradient_permille_x10;
      e.t_cycles = static_cast<std::int32_t>(s.max_compensation_ms / p::cycle_ms);
      // M_s = Delta_d(T_s, g_s), or the configured margin (checked to be >= it).
      e.margin_mm = s.margin_mm > 0 ? s.margin_mm
                                    : ErrorBoundMm(s.max_compensation_ms, s.gradient_permille_x10,
                                                   cfg.imu_rate_error_udeg_s);
    }
    sections_[static_cast<std::size_t>(i)] = e;
  }
  pulse_um_ = kPi * static_cast<double>(cfg.wheel_diameter_um) / static_cast<double>(p::tg_teeth);
  // Most pulses one cycle may carry at max_speed_mm_s, plus one (the edge phase).
  const double per_cycle_um = static_cast<double>(p::max_speed_mm_s) * static_cast<double>(p::cycle_ms);
  max_pulses_per_cycle_ = static_cast<std::int64_t>(std::floor(per_cycle_um / pulse_um_)) + 1;

  have_time_ = false;
  last_time_ms_ = 0;
  have_prev_ = false;
  have_tg_ = false;
  prev_pulses_ = prev_edge_us_ = prev_imu_us_ = prev_accepted_ms_ = 0;
  for (auto& h : hist_) h = HistoryEntry{};
  count_ = 0;
  ax_sum_nano_ = 0;
  front_um_ = cfg.initial_front_mm * 1000;
  tg_ref_um_ = front_um_;
  tg_ref_pulses_ = 0;
  last_balise_um_ = front_um_;
  kept_front_mm_ = kept_rear_mm_ = 0;
  for (auto& c : cand_) c = CandidateState{};
  episode_gradient_x10_ = 0;
  // M_prev before the first cycle: the fixed point of the look-up at the initial position
  // (a larger margin can only reach more sections; at most section_count steps).
  prev_margin_mm_ = 0;
  for (int i = 0; i <= kMaxSections; ++i) {
    const Limits l = SectionLimitsAt(cfg.initial_front_mm, prev_margin_mm_);
    if (l.limits.margin_mm == prev_margin_mm_) break;
    prev_margin_mm_ = l.limits.margin_mm;
  }
  machine_ = ReadhesionMachine(MachineConfigOf(cfg));
  out_ = OdometryOutput{};
  out_.mode = machine_.state().mode;  // stopped at start-up until the warm-up (REQ-RA-015)
  out_.stop_reason = machine_.state().stop_reason;
  out_.position_valid = machine_.state().position_valid;
  out_.stop_demand = machine_.state().stop_demand;
  out_.front_mm = cfg.initial_front_mm;
  out_.last_balise_mm = cfg.initial_front_mm;
  out_.margin_mm = cfg.method == Method::kImu ? prev_margin_mm_ : 0;
  out_.front_error_mm = out_.rear_error_mm = out_.margin_mm;
}

// ---- section limits (design note §6) ------------------------------------------------------

// @implements REQ-RA-009
Odometry::Limits Odometry::SectionLimitsAt(std::int64_t front_mm, std::int64_t extension_mm) const noexcept {
  const std::int64_t first = sections_[0].begin_mm;
  const std::int64_t last = sections_[static_cast<std::size_t>(section_count_ - 1)].end_mm - 1;
  std::int64_t lo = front_mm - cfg_.train_length_mm - extension_mm;
  std::int64_t hi = front_mm + extension_mm;
  // Outside the table the nearest section applies.
  lo = std::clamp(lo, first, last);
  hi = std::clamp(hi, first, last);
  // First section with end > lo (binary search, <= 9 steps for 256 sections).
  int a = 0;
  int b = section_count_ - 1;
  while (a < b) {
    const int mid = a + (b - a) / 2;
    if (sections_[static_cast<std::size_t>(mid)].end_mm > lo) {
      b = mid;
    } else {
      a = mid + 1;
    }
  }
  Limits out;
  out.limits.max_compensation_cycles = sections_[static_cast<std::size_t>(a)].t_cycles;
  out.limits.margin_mm = 0;
  out.gradient_x10 = 0;
  for (int j = a; j < section_count_; ++j) {
    const SectionEntry& s = sections_[static_cast<std::size_t>(j)];
    if (s.begin_mm > hi) break;
    out.limits.max_compensation_cycles = std::min(out.limits.max_compensation_cycles, s.t_cycles);
    out.limits.margin_mm = std::max(out.limits.margin_mm, s.margin_mm);
    out.gradient_x10 = std::max(out.gradient_x10, s.gradient_x10);
  }
  // The former method carries no permanent margin (design note §8, baseline).
  if (cfg_.method == Method::kMaxMinAcceleration) out.limits.margin_mm = 0;
  return out;
}

// ---- validation (design note §2) ---------------------------------------------------------

// @implements REQ-RA-013
InputError Odometry::ValidateImu(const CycleInput& in) const noexcept {
  if (in.imu_count != kImuSamplesPerCycle) return InputError::kImuSampleCount;
  const std::int64_t t_us = in.time_ms * 1000;
  const std::int64_t lo = t_us - kCycleUs - p::imu_jitter_us;
  const std::int64_t hi = t_us + p::imu_jitter_us;
  const std::int64_t step_lo = p::imu_sample_ms * 1000 - p::imu_jitter_us;
  const std::int64_t step_hi = p::imu_sample_ms * 1000 + p::imu_jitter_us;
  for (std::size_t i = 0; i < in.imu.size(); ++i) {
    const std::int64_t t = in.imu[i].time_us;
    if (t < lo || t > hi) return InputError::kImuTimestamps;
    const bool have_before = i > 0 || have_prev_;
    const std::int64_t before = i > 0 ? in.imu[i - 1].time_us : prev_imu_us_;
    if (have_before && (t - before < step_lo || t - before > step_hi)) return InputError::kImuTimestamps;
  }
  for (const ImuSample& s : in.imu) {
    for (const double v : {s.ax, s.ay, s.az, s.wx, s.wy, s.wz}) {
      if (!std::isfinite(v)) return InputError::kImuNotFinite;
    }
  }
  for (const ImuSample& s : in.imu) {
    if (std::fabs(s.ax) > kMaxAccel || std::fabs(s.ay) > kMaxAccel || std::fabs(s.az) > kMaxAccel) {
      return InputError::kImuOutOfRange;
    }
    if (std::fabs(s.wx) > kMaxRate || std::fabs(s.wy) > kMaxRate || std::fabs(s.wz) > kMaxRate) {
      return InputError::kImuOutOfRange;
    }
  }
  return InputError::kNone;
}

// @implements REQ-RA-013
InputError Odometry::ValidateTg(const CycleInput& in) const noexcept {
  const TgSample& tg = in.tg;
  if (tg.pulses < 0 || tg.pulses > kMaxPulses) return InputError::kTgImplausibleRate;
  // Continuity with the previous cycle when it was accepted. After a rejected cycle the next
  // one starts a new baseline (a restarted counter becomes valid again, ASM-026).
  if (have_prev_ && tg.pulses < prev_pulses_) return InputError::kTgPulsesDecreasing;
  const std::int64_t t_us = in.time_ms * 1000;
  if (tg.time_us < t_us - kCycleUs - p::imu_jitter_us || tg.time_us > t_us + p::imu_jitter_us) {
    return InputError::kTgEdgeInvalid;
  }
  if (tg.last_edge_us > tg.time_us) return InputError::kTgEdgeInvalid;
  if (have_prev_) {
    if (tg.pulses > prev_pulses_ ? tg.last_edge_us <= prev_edge_us_ : tg.last_edge_us != prev_edge_us_) {
      return InputError::kTgEdgeInvalid;
    }
    if (tg.pulses - prev_pulses_ > max_pulses_per_cycle_) return InputError::kTgImplausibleRate;
  }
  return InputError::kNone;
}

// ---- the cycle -----------------------------------------------------------------------------

Odometry::HistoryEntry& Odometry::At(std::int64_t index) noexcept {
  return hist_[static_cast<std::size_t>(index % kHistoryCycles)];
}
const Odometry::HistoryEntry& Odometry::At(std::int64_t index) const noexcept {
  return hist_[static_cast<std::size_t>(index % kHistoryCycles)];
}
std::int64_t Odometry::Oldest() const noexcept { return std::max<std::int64_t>(0, count_ - kHistoryCycles); }
// The first cycles after a (re)start have partial averages and no TG speed at entry 0.
std::int64_t Odometry::OldestUsable() const noexcept {
  return std::max<std::int64_t>(Oldest(), kAvgCycles + kWindowCycles);
}

void Odometry::RebaseTg(std::int64_t front_um, std::int64_t pulses) noexcept {
  tg_ref_um_ = front_um;
  tg_ref_pulses_ = pulses;
}

// @implements REQ-RA-002
std::int64_t Odometry::TgFrontUm(std::int64_t pulses) const noexcept {
  // TG distance N * p, rounded to the nearest um.
  return tg_ref_um_ + std::llround(static_cast<double>(pulses - tg_ref_pulses_) * pulse_um_);
}

// @implements REQ-RA-001 REQ-RA-002 REQ-RA-004 REQ-RA-011
void Odometry::PushHistory(const CycleInput& in, bool balise) noexcept {
  const std::int64_t i = count_;
  const std::int64_t n_pulses = in.tg.pulses;
  // the entry leaving the 3 s window is read before the ring slot is reused
  const std::int64_t leaving_nano = i >= kAvgCycles ? At(i - kAvgCycles).ax_nano : 0;

  HistoryEntry e{};
  e.time_ms = in.time_ms;
  e.pulses = n_pulses;
  e.edge_us = in.tg.last_edge_us;
  e.tg_time_us = in.tg.time_us;
  e.balise = balise;
  e.balise_um = balise ? in.balise->front_mm * 1000 : 0;
  // cycle means of the IMU, fixed summation order
  double sx = 0, sy = 0, sz = 0, rx = 0, ry = 0, rz = 0;
  for (const ImuSample& s : in.imu) {
    sx += s.ax;
    sy += s.ay;
    sz += s.az;
    rx += s.wx;
    ry += s.wy;
    rz += s.wz;
  }
  const double n = static_cast<double>(kImuSamplesPerCycle);
  e.ax = sx / n;
  e.ay = sy / n;
  e.az = sz / n;
  e.wx = rx / n;
  e.wy = ry / n;
  e.wz = rz / n;
  e.ax_nano = std::llround(e.ax * 1e9);
  ax_sum_nano_ += e.ax_nano - leaving_nano;
  const std::int64_t avg_n = std::min<std::int64_t>(i + 1, kAvgCycles);
  e.ax_avg = static_cast<double>(ax_sum_nano_) / static_cast<double>(avg_n) / 1e9;

  // TG speed (design note §3): 100-pulse timing, else the 1 s window count.
  if (i > 0) {
    const std::int64_t j = std::max<std::int64_t>(i - kWindowCycles, 0);
    const HistoryEntry& w = At(j);
    const std::int64_t dn = n_pulses - w.pulses;
    const double window_v = static_cast<double>(dn) * pulse_um_ / static_cast<double>((i - j) * kCycleUs);
    e.v_tg = window_v;
    e.tg_lag_s = 0.5e-6 * static_cast<double>(in.tg.time_us - w.tg_time_us);
    if (!RAILPROOF_FAULT(FAULT_RA_WINDOW_SPEED_ONLY) && dn >= p::tg_timing_pulses && window_v >= kLowSpeed) {
      for (std::int64_t k = i - 1; k >= j; --k) {
        const HistoryEntry& h = At(k);
        const std::int64_t pulses = n_pulses - h.pulses;
        if (pulses < p::tg_timing_pulses) continue;
        const double dt_us = static_cast<double>(e.edge_us) - static_cast<double>(h.edge_us);
        if (dt_us > 0.0) {
          e.v_tg = static_cast<double>(pulses) * pulse_um_ / dt_us;
          e.tg_lag_s = 1e-6 * (static_cast<double>(in.tg.time_us) -
                               0.5 * (static_cast<double>(e.edge_us) + static_cast<double>(h.edge_us)));
        }
        break;
      }
    }
  }
  // A_p = (v(now) - v(now - 3 s)) / 3 s; the first entry after a (re)start has no speed.
  if (i >= 2) {
    const std::int64_t j = std::max<std::int64_t>(i - kAvgCycles, 1);
    e.ap = (e.v_tg - At(j).v_tg) / (static_cast<double>(i - j) * kDt);
  }
  // Jerks of the averaged signals and the start-point conditions (REQ-RA-004), evaluated
  // once both averages and the previous cycle's cover full windows (as the deviation).
  if (i > kAvgCycles + kWindowCycles) {
    const HistoryEntry& prev = At(i - 1);
    const double jp = (e.ap - prev.ap) / kDt;
    const double ji = (e.ax_avg - prev.ax_avg) / kDt;
    e.jerk_ok = std::fabs(jp) < static_cast<double>(p::jerk_tg_limit_mm_s3) / 1000.0 &&
                std::fabs(ji) < static_cast<double>(p::jerk_imu_limit_mm_s3) / 1000.0 &&
                std::fabs(ji - jp) < static_cast<double>(p::jerk_diff_limit_mm_s3) / 1000.0;
  }
  e.front_um = TgFrontUm(n_pulses);
  At(i) = e;
  count_ = i + 1;
}

// @implements REQ-RA-013
const OdometryOutput& Odometry::Step(const CycleInput& in) noexcept {
  if (!created_) {
    out_ = OdometryOutput{};
    out_.time_ms = in.time_ms;
    out_.mode = Mode::kStopped;
    out_.position_valid = false;
    out_.stop_demand = true;
    return out_;
  }
  InputError gap = InputError::kNone;
  const bool time_in_range = InRange(in.time_ms, -kMaxAbsTimeMs, kMaxAbsTimeMs);
  if (!time_in_range || (have_time_ && in.time_ms != last_time_ms_ + p::cycle_ms)) gap = InputError::kCycleTimeGap;
  // The time base follows the received cycles, so a stream recovers after a gap.
  if (time_in_range) {
    have_time_ = true;
    last_time_ms_ = in.time_ms;
  }
  const InputError imu_error = gap == InputError::kNone ? ValidateImu(in) : InputError::kNone;
  const InputError tg_error = gap != InputError::kNone ? gap : ValidateTg(in);
  if (imu_error != InputError::kNone || tg_error != InputError::kNone) {
    Reject(in, imu_error, tg_error);
  } else {
    Accept(in);
  }
  return out_;
}

// A rejected cycle (REQ-RA-013): nothing of it enters any history; the history restarts
// with the next accepted cycle (the averages need contiguous cycles); the TG distance
// continues from the last accepted cycle. The machine takes the sensor failure.
// @implements REQ-RA-013
void Odometry::Reject(const CycleInput& in, InputError imu_error, InputError tg_error) noexcept {
  count_ = 0;
  ax_sum_nano_ = 0;
  have_prev_ = false;
  // the nominal front (a candidate's while compensating) is where the TG continues from
  if (have_tg_) RebaseTg(front_um_, prev_pulses_);
  Predicates pr;
  pr.imu_ok = imu_error == InputError::kNone;
  pr.tg_ok = tg_error == InputError::kNone;
  const Limits lim = SectionLimitsAt(RoundDiv(front_um_, 1000), prev_margin_mm_);
  pr.section = lim.limits;
  const MachineError me = machine_.Step(pr);
  for (auto& c : cand_) c = CandidateState{};
  episode_gradient_x10_ = lim.gradient_x10;
  if (me == MachineError::kNone) prev_margin_mm_ = machine_.state().margin_mm;
  FillOutput(in, imu_error != InputError::kNone ? imu_error : tg_error, false, nullptr, me != MachineError::kNone);
  out_.predicates = pr;
}

// @implements REQ-RA-003 REQ-RA-004 REQ-RA-005 REQ-RA-006 REQ-RA-007 REQ-RA-009 REQ-RA-010 REQ-RA-011 REQ-RA-012
void Odometry::Accept(const CycleInput& in) noexcept {
  const std::int64_t n_pulses = in.tg.pulses;
  if (!have_tg_) {
    RebaseTg(front_um_, n_pulses);  // the first accepted cycle
  } else if (!have_prev_) {
    // After rejected cycles the TG distance continues from the last accepted count if the
    // count went on plausibly for the elapsed time; otherwise (a restarted or jumping
    // counter) it restarts from the last nominal front. The position is invalid until a
    // balise fix either way.
    const std::int64_t cycles =
        std::clamp<std::int64_t>((in.time_ms - prev_accepted_ms_) / p::cycle_ms, 1, kMaxPulses / max_pulses_per_cycle_);
    if (n_pulses < prev_pulses_ || n_pulses - prev_pulses_ > max_pulses_per_cycle_ * cycles) {
      RebaseTg(front_um_, n_pulses);
    }
  }
  const bool balise = in.balise.has_value() && in.balise->front_mm >= sections_[0].begin_mm &&
                      in.balise->front_mm <= sections_[static_cast<std::size_t>(section_count_ - 1)].end_mm;
  if (balise) {
    // The position base is the fix in every mode (design note §5 steps 3-5); the
    // accumulated error and the baseline's kept extension restart from it.
    const std::int64_t b_um = in.balise->front_mm * 1000;
    RebaseTg(b_um, n_pulses);
    last_balise_um_ = b_um;
    kept_front_mm_ = kept_rear_mm_ = 0;
  }
  PushHistory(in, balise);
  have_prev_ = true;
  have_tg_ = true;
  prev_accepted_ms_ = in.time_ms;
  prev_pulses_ = n_pulses;
  prev_edge_us_ = in.tg.last_edge_us;
  prev_imu_us_ = in.imu[static_cast<std::size_t>(kImuSamplesPerCycle - 1)].time_us;

  const std::int64_t i = count_ - 1;
  const HistoryEntry& e = At(i);
  const MachineState& before = machine_.state();
  const Mode mode_before = before.mode;
  const bool imu = cfg_.method == Method::kImu;

  // Active candidates advance by this cycle (incremental, design note §7).
  int lowest = -1;
  if (mode_before == Mode::kCompensating) {
    for (std::size_t c = 0; c < cand_.size(); ++c) {
      if (!cand_[c].active) continue;
      AdvanceCandidate(cand_[c], e);
      if (imu) Record(c, At(i));
      if (lowest < 0) lowest = static_cast<int>(c);
    }
  }
  const std::int64_t pre_front_um =
      (imu && lowest >= 0) ? std::llround(CandidateFrontUm(cand_[static_cast<std::size_t>(lowest)])) : e.front_um;

  // Section limits under the train (design note §6) and the episode's steepest gradient.
  const Limits lim = SectionLimitsAt(RoundDiv(pre_front_um, 1000), prev_margin_mm_);
  episode_gradient_x10_ =
      mode_before == Mode::kCompensating ? std::max(episode_gradient_x10_, lim.gradient_x10) : lim.gradient_x10;

  // Predicates (design note §4).
  Predicates pr;
  pr.section = lim.limits;
  pr.balise = balise;
  // A TG pulse since the previous cycle of the history (REQ-RA-015). The first cycle of a
  // (re)started history has no count to compare and counts as a rest cycle: the warm-up's
  // warmup_cycles cycles are then exactly the entries the deviation predicate needs full
  // (a train moving at the first cycle shows its pulses in the second).
  pr.tg_moving = i > 0 && e.pulses != At(i - 1).pulses;
  const bool low = e.v_tg < kLowSpeed;
  const double res = low ? pulse_um_ * 1e-6 : 0.0;  // p / 1 s (m/s) and p / 1 s^2 (m/s^2)
  const double ta = static_cast<double>(cfg_.detect_threshold_mm_s2) / 1000.0;
  // Raised only once both averages cover full windows (3 s of A_p on 1 s TG windows): the
  // partial averages of a (re)start are too coarse and would raise false detections.
  pr.deviation = i >= kAvgCycles + kWindowCycles && std::fabs(e.ax_avg - e.ap) > ta + res;
  const double rate = static_cast<double>(p::readhesion_rate_mm_s2) / 1000.0;
  for (std::size_t c = 0; c < cand_.size(); ++c) {
    const CandidateState& k = cand_[c];
    if (!k.active) continue;
    if (imu) {
      const double t = static_cast<double>(k.cycles) * kDt;
      pr.speed_agrees[c] = std::fabs(e.v_tg - k.v) <= rate * t + res;
    } else {
      pr.speed_agrees[c] = e.v_tg >= k.v_lo - res && e.v_tg <= k.v_hi + res;
    }
  }
  std::int64_t start = i;
  const bool detecting = mode_before == Mode::kTg && pr.deviation &&
                         before.deviation_count + 1 >= static_cast<int>(p::confirm_cycles);
  if (detecting) {
    start = StartPoint(i);
    pr.start_age_cycles = static_cast<std::int32_t>(i - start);
  }

  const double v_tg_raw = e.v_tg;
  const MachineError me = machine_.Step(pr);
  const MachineState& st = machine_.state();

  if (me == MachineError::kNone && st.detected) {
    const bool slip = e.ap > e.ax_avg;  // TG accelerates more than the train: a slip
    const std::int64_t spacing = p::parallel_spacing_ms / p::cycle_ms;
    for (std::size_t c = 0; c < cand_.size(); ++c) {
      cand_[c] = CandidateState{};
      if (!st.candidates[c].active) continue;
      const std::int64_t s = std::max(start - static_cast<std::int64_t>(c) * spacing, OldestUsable());
      InitCandidate(cand_[c], s, slip);
      for (std::int64_t j = s + 1; j <= i; ++j) {  // catch-up
        AdvanceCandidate(cand_[c], At(j));
        if (imu) Record(c, At(j));
      }
    }
  }
  if (me == MachineError::kNone && st.adopted != kNoCandidate) {
    const CandidateState& a = cand_[static_cast<std::size_t>(st.adopted)];
    if (imu) {
      // The compensated distance replaces the TG distance (REQ-RA-005), in the history too.
      RebaseTg(std::llround(CandidateFrontUm(a)), n_pulses);
      ReplaceTg(static_cast<std::size_t>(st.adopted), i);
    } else {
      // Baseline: the extension at re-adhesion is kept until the next balise (REQ-RA-014).
      double hi = -1e300, lo = 1e300;
      for (const CandidateState& k : cand_) {
        if (!k.active) continue;
        hi = std::max(hi, k.x_hi_um);
        lo = std::min(lo, k.x_lo_um);
      }
      kept_front_mm_ += CeilUmToMm(hi - static_cast<double>(e.front_um));
      kept_rear_mm_ += CeilUmToMm(static_cast<double>(e.front_um) - lo);
    }
  }
  if (mode_before == Mode::kCompensating && st.mode == Mode::kStopped) {
    RebaseTg(pre_front_um, n_pulses);  // timeout: the position stays where it was estimated
    if (imu && lowest >= 0) ReplaceTg(static_cast<std::size_t>(lowest), i);
  }
  for (std::size_t c = 0; c < cand_.size(); ++c) {
    if (me != MachineError::kNone || !st.candidates[c].active) cand_[c].active = false;
  }
  if (me == MachineError::kNone) prev_margin_mm_ = st.margin_mm;
  FillOutput(in, InputError::kNone, true, &e, me != MachineError::kNone);
  out_.v_tg = v_tg_raw;  // the diagnostic shows the TG's own speed (the history may hold v_c)
  if (st.detected) out_.start_age_cycles = pr.start_age_cycles;
  out_.predicates = pr;
  At(i).front_um = front_um_;
}

// ---- output (design note §8) ----------------------------------------------------------------

// @implements REQ-RA-009 REQ-RA-012 REQ-RA-014
void Odometry::FillOutput(const CycleInput& in, InputError error, bool accepted, const HistoryEntry* e,
                          bool machine_fault) noexcept {
  const MachineState& st = machine_.state();
  const bool imu = cfg_.method == Method::kImu;
  OdometryOutput& o = out_;
  o.time_ms = in.time_ms;
  o.mode = st.mode;
  o.stop_reason = st.stop_reason;
  o.input_error = error;
  o.position_valid = st.position_valid && !machine_fault;
  o.stop_demand = st.stop_demand || machine_fault;
  o.detected = st.detected;
  o.adopted = st.adopted;

  const bool compensating = st.mode == Mode::kCompensating;
  int lowest = -1;
  for (std::size_t c = 0; c < cand_.size(); ++c) {
    if (cand_[c].active && lowest < 0) lowest = static_cast<int>(c);
  }
  if (accepted && e != nullptr) {
    front_um_ = (imu && compensating && lowest >= 0)
                    ? std::llround(CandidateFrontUm(cand_[static_cast<std::size_t>(lowest)]))
                    : TgFrontUm(e->pulses);
  }
  o.front_mm = RoundDiv(front_um_, 1000);
  o.last_balise_mm = RoundDiv(last_balise_um_, 1000);

  // Accumulated TG error since the last balise, rounded up. It also covers the rounding of
  // the nominal front to mm: that is non-zero only when the front moved away from the
  // (integer) balise position, and then the ceiling is at least 1 mm.
  const std::int64_t dist_um = std::min<std::int64_t>(std::llabs(front_um_ - last_balise_um_), 10'000'000'000'000);
  o.accumulated_error_mm = CeilDiv(dist_um * cfg_.length_correction_ppm, 1'000'000'000);
  o.margin_mm = imu ? st.margin_mm : 0;

  std::int64_t ext_front = 0, ext_rear = 0, bound = 0;
  o.v_comp = {};
  o.x_comp_mm = {};
  for (std::size_t c = 0; c < cand_.size(); ++c) {
    const CandidateState& k = cand_[c];
    if (!k.active) continue;
    o.v_comp[c] = CandidateSpeed(k);
    if (imu) {
      o.x_comp_mm[c] = RoundDiv(std::llround(CandidateFrontUm(k)), 1000);
      const std::int64_t t_ms = static_cast<std::int64_t>(st.candidates[c].age_cycles) * p::cycle_ms;
      const std::int64_t b = ErrorBoundMm(t_ms, episode_gradient_x10_, cfg_.imu_rate_error_udeg_s);
      bound = std::max(bound, b);
      const std::int64_t reach =
          CeilUmToMm(std::fabs(CandidateFrontUm(k) - static_cast<double>(front_um_))) + b;
      ext_front = std::max(ext_front, reach - o.margin_mm);
    } else {
      ext_front = std::max(ext_front, CeilUmToMm(k.x_hi_um - static_cast<double>(front_um_)));
      ext_rear = std::max(ext_rear, CeilUmToMm(static_cast<double>(front_um_) - k.x_lo_um));
    }
  }
  if (imu) {
    ext_rear = ext_front;  // the disagreement extension is symmetric (design note §8)
    std::int64_t margin_term = o.margin_mm;
    if (RAILPROOF_FAULT(FAULT_RA_NO_PERMANENT_MARGIN) && !compensating) {
      margin_term = 0;
    }
    o.front_error_mm = o.accumulated_error_mm + margin_term + ext_front;
    o.rear_error_mm = o.accumulated_error_mm + margin_term + ext_rear;
    o.compensation_bound_mm = bound;
  } else {
    o.front_error_mm = o.accumulated_error_mm + kept_front_mm_ + ext_front;
    o.rear_error_mm = o.accumulated_error_mm + kept_rear_mm_ + ext_rear;
    o.compensation_bound_mm = std::max(ext_front, ext_rear);
  }

  if (accepted && e != nullptr) {
    o.ax_avg = e->ax_avg;
    o.ap_avg = e->ap;
    o.v_tg = e->v_tg;
    o.tg_lag_s = e->tg_lag_s;
    double v = e->v_tg;
    if (compensating && lowest >= 0) {
      // Safe side: the highest active candidate's speed (upper bound for the baseline).
      v = -1e300;
      for (std::size_t c = 0; c < cand_.size(); ++c) {
        if (cand_[c].active) v = std::max(v, o.v_comp[c]);
      }
    }
    o.speed_mm_s = static_cast<std::int64_t>(std::clamp(std::ceil(v * 1000.0), 0.0, 1e9));
    // Standstill: no pulse within the full 1 s window, in TG odometry or stopped.
    const std::int64_t i = count_ - 1;
    o.standstill = !compensating && i >= kWindowCycles && At(i - kWindowCycles).pulses == e->pulses;
  } else {
    o.ax_avg = o.ap_avg = o.v_tg = o.tg_lag_s = 0.0;
    o.standstill = false;  // speed kept from the last accepted cycle
  }
}

}  // namespace railproof::ra
