// On-board braking patterns (spec/design/br.md §1-§3): the emergency pattern to the
// usable stop limit and to every speed restriction ahead (REQ-BR-001), the service pattern
// from service_offset_mm short of the stop limit (REQ-BR-002) and at the mild-brake and
// release leads (REQ-BR-003), restrictions as ceilings until the rear has left them
// (REQ-BR-004), the effective gradient over the train length with the data error
// (REQ-BR-005), the supervised position and speed (REQ-BR-007) and the standstill rule
// without a usable stop limit (REQ-BR-012). The decision is br::Supervisor.
//
// Usage (one PatternCalculator per train):
//   auto created = PatternCalculator::Create(train, DefaultSupervisionParams());  // allocates once
//   created.calculator->SetProfile(gradients, restrictions);   // whenever the profile changes
//   const Evaluation e = created.calculator->Evaluate(position, stop_limit);      // every cycle
//   const Decision d = supervisor.Step(e.speeds, driver_inputs);
//
// Runtime module: no heap after Create, no exceptions, no recursion, bounded loops, typed
// results, deterministic (Evaluate is const and depends on its arguments and the profile
// only). Units: mm, mm/s, mm/s^2, ms, gradient permille x 10 (+ rising in the running
// direction), all int64; every rounding to the safe side (design note §1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/br/supervisor.hpp"
#include "railproof/generated/br_params.hpp"
#include "railproof/core/fixed_vector.hpp"
#include "railproof/core/track.hpp"
#include "railproof/core/units.hpp"

namespace railproof::br {

// ---- ranges accepted by Create / SetProfile / Evaluate (REQ-BR-008) ------------------------
// railproof/core/units.hpp; they keep every intermediate product inside int64.
using core::kMaxAccelerationMmS2;
using core::kMaxGradientX10;
using core::kMaxLimitMmS;
using core::kMaxMeasuredSpeedMmS;
using core::kMaxPositionErrorMm;
using core::kMaxPositionMm;
using core::kMaxProfileCapacity;
using core::kMaxSpeedAllowanceMmS;
using core::kMaxTimeMs;
using core::kMaxTrainLengthMm;
inline constexpr std::size_t kDefaultProfileCapacity =
    static_cast<std::size_t>(params::br::max_profile_entries);

// Pattern values of a train type (spec/trains/<type>.yaml, the maximum of every range):
//   length_mm                  length_mm
//   accel_max_mm_s2            accel_max_mm_s2
//   beta_e_mm_s2               braking.emergency_pattern_mm_s2
//   beta_n7_mm_s2              braking.service_pattern_mm_s2
//   emergency_free_running_ms  braking.emergency_free_running_ms[1]
//   service_free_running_ms    braking.service_free_running_ms[1]
//   overspeed_mm_s             braking.emergency_overspeed_kmh in mm/s (rounded up)
//   speed_error_ppm            supervision.speed_error_ppm
//   speed_error_abs_mm_s       supervision.speed_error_abs_mm_s
struct TrainData {
  std::int64_t length_mm = 0;
  std::int64_t accel_max_mm_s2 = 0;
  std::int64_t beta_e_mm_s2 = 0;
  std::int64_t beta_n7_mm_s2 = 0;
  std::int64_t emergency_free_running_ms = 0;
  std::int64_t service_free_running_ms = 0;
  std::int64_t overspeed_mm_s = 0;
  std::int64_t speed_error_ppm = 0;
  std::int64_t speed_error_abs_mm_s = 0;
};

// Supervision parameters (spec/parameters/br.yaml).
struct SupervisionParams {
  std::int64_t cycle_ms = 0;
  std::int64_t reaction_ms = 0;
  std::int64_t service_offset_mm = 0;
  std::int64_t lead_4n_ms = 0;
  std::int64_t lead_5n_ms = 0;
  std::int64_t lead_6n_ms = 0;
  std::int64_t release_lead_ms = 0;
  std::int64_t gradient_error_x10 = 0;
  std::int64_t gravity_mm_s2 = 0;
  std::int64_t max_speed_mm_s = 0;  // upper bound of every pattern-speed search
};

// The values of spec/parameters/br.yaml (generated railproof::params::br).
SupervisionParams DefaultSupervisionParams() noexcept;

using core::GradientSegment;     // railproof/core/track.hpp
using core::RestrictionSegment;  // railproof/core/track.hpp

using core::PositionEstimate;  // railproof/core/track.hpp

// @implements REQ-BR-001 REQ-BR-002
enum class Pattern : std::uint8_t { kEmergency, kService };

constexpr const char* ToString(Pattern p) noexcept {
  return core::EnumName(p, std::array<const char*, 2>{"EMERGENCY", "SERVICE"});
}

// Train data / parameter errors of Create, reported in this order (REQ-BR-008, REQ-BR-010).
// @implements REQ-BR-008 REQ-BR-010
enum class CreateError : std::uint8_t {
  kNone,
  kTrainLengthInvalid,        // length_mm not in 1..kMaxTrainLengthMm
  kAccelerationInvalid,       // accel_max_mm_s2 not in 0..kMaxAccelerationMmS2
  kDecelerationInvalid,       // beta_e or beta_n7 not in 1..kMaxAccelerationMmS2
  kServiceAboveEmergency,     // beta_n7 > beta_e (design rule, REQ-BR-010)
  kFreeRunningInvalid,        // a free-running time not in 0..kMaxTimeMs
  kSpeedAllowanceInvalid,     // overspeed / abs speed error not in 0..kMaxSpeedAllowanceMmS,
                              // speed_error_ppm not in 0..1e6
  kTimeInvalid,               // cycle_ms not in 1..kMaxTimeMs, reaction_ms not in 0..kMaxTimeMs
  kServiceOffsetInvalid,      // service_offset_mm not in 0..kMaxPositionErrorMm
  kLeadsInvalid,              // not 0 < lead_6n < lead_5n < lead_4n < release_lead <= kMaxTimeMs
  kGradientErrorInvalid,      // gradient_error_x10 not in 0..kMaxGradientX10
  kGravityInvalid,            // gravity_mm_s2 not in 1..kMaxAccelerationMmS2
  kMaxSpeedInvalid,           // max_speed_mm_s not in 1..kMaxLimitMmS
  kCapacityInvalid,           // capacity not in 1..kMaxProfileCapacity
  kOutOfMemory,               // allocation at Create failed
};

constexpr const char* ToString(CreateError e) noexcept {
  return core::EnumName(e, std::array<const char*, 15>{"NONE", "TRAIN_LENGTH_INVALID", "ACCELERATION_INVALID", "DECELERATION_INVALID", "SERVICE_ABOVE_EMERGENCY", "FREE_RUNNING_INVALID", "SPEED_ALLOWANCE_INVALID", "TIME_INVALID", "SERVICE_OFFSET_INVALID", "LEADS_INVALID", "GRADIENT_ERROR_INVALID", "GRAVITY_INVALID", "MAX_SPEED_INVALID", "CAPACITY_INVALID", "OUT_OF_MEMORY"});
}

// Profile verdicts of SetProfile (REQ-BR-008, REQ-BR-005). Checked in this order: the two
// list sizes; every gradient entry (position, empty, unsorted, overlap, gradient range);
// every restriction entry (position, empty, unsorted, overlap, limit range); last the
// braking capability of both patterns on the most falling effective gradient (entry: the
// steepest falling gradient segment, 0 if the level line itself fails).
// @implements REQ-BR-005 REQ-BR-008
enum class ProfileVerdict : std::uint8_t {
  kAccept,
  kTooManyGradients,      // more gradient segments than the capacity
  kTooManyRestrictions,   // more restrictions than the capacity
  kPositionOutOfRange,    // |begin| or |end| > kMaxPositionMm
  kEmptySegment,          // begin >= end
  kUnsorted,              // begin < begin of the previous segment of the same list
  kOverlap,               // begin < end of the previous segment of the same list
  kGradientOutOfRange,    // |permille_x10| > kMaxGradientX10
  kLimitOutOfRange,       // limit_mm_s <= 0 or > kMaxLimitMmS
  kBrakingNotPositive,    // beta + grav(effective gradient) <= 0 somewhere (either pattern)
};

constexpr const char* ToString(ProfileVerdict v) noexcept {
  return core::EnumName(v, std::array<const char*, 10>{"ACCEPT", "TOO_MANY_GRADIENTS", "TOO_MANY_RESTRICTIONS", "POSITION_OUT_OF_RANGE", "EMPTY_SEGMENT", "UNSORTED", "OVERLAP", "GRADIENT_OUT_OF_RANGE", "LIMIT_OUT_OF_RANGE", "BRAKING_NOT_POSITIVE"});
}

struct ProfileResult {
  ProfileVerdict verdict = ProfileVerdict::kAccept;
  bool in_restrictions = false;  // the offending entry is a restriction (else a gradient)
  std::size_t entry = 0;         // index of the offending entry in its list (0 if n/a)
};

// Status of one Evaluate, checked in this order. Anything but kOk gives pattern speeds 0 and
// v_s >= 1, so the supervisor commands (and latches) the emergency brake (fail-safe).
// @implements REQ-BR-008
enum class EvalStatus : std::uint8_t {
  kOk,
  kNoProfile,          // no accepted profile (none set yet, or the last one was refused)
  kInvalidPosition,    // |front_mm| > kMaxPositionMm or an error not in 0..kMaxPositionErrorMm
  kInvalidSpeed,       // speed_mm_s not in 0..kMaxMeasuredSpeedMmS
  kInvalidStopLimit,   // |stop limit| > kMaxPositionMm
};

constexpr const char* ToString(EvalStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 5>{"OK", "NO_PROFILE", "INVALID_POSITION", "INVALID_SPEED", "INVALID_STOP_LIMIT"});
}

struct Evaluation {
  EvalStatus status = EvalStatus::kNoProfile;
  PatternSpeeds speeds;
};

struct PatternCalculatorResult;

// The pattern computation of design note §3 in O(log n) per pattern speed check.
// @implements REQ-BR-001 REQ-BR-002 REQ-BR-004 REQ-BR-005 REQ-BR-007 REQ-BR-008
class PatternCalculator {
 public:
  using CreateResult = PatternCalculatorResult;

  // Validates train data and parameters and allocates all storage for profiles of up to
  // `capacity` gradient segments and `capacity` restrictions. No profile is set.
  static CreateResult Create(const TrainData& train, const SupervisionParams& params,
                             std::size_t capacity = kDefaultProfileCapacity) noexcept;

  PatternCalculator(const PatternCalculator&) = delete;
  PatternCalculator& operator=(const PatternCalculator&) = delete;
  PatternCalculator(PatternCalculator&&) noexcept = default;
  PatternCalculator& operator=(PatternCalculator&&) noexcept = default;
  ~PatternCalculator() = default;

  // Validates and installs the profile (both lists sorted by position, non-overlapping,
  // non-empty segments): effective gradient, braking capabilities, braking integrals and
  // the target suffix minima. A refused profile leaves the calculator WITHOUT a profile
  // (Evaluate then reports kNoProfile: standstill supervision), never with the old one.
  // O(n log n), no allocation.
  ProfileResult SetProfile(std::span<const GradientSegment> gradients,
                           std::span<const RestrictionSegment> restrictions) noexcept;
  [[nodiscard]] bool HasProfile() const noexcept { return has_profile_; }

  // One supervision cycle (design note §2-§3): v_s, V_e(x_s), V_s(x_s) and the service
  // pattern at x_s + ceil(v_s * lead / 1000) for lead_6n, lead_5n, lead_4n, release_lead.
  // No usable stop limit (nullopt) -> stop limit at the supervised front (REQ-BR-012).
  // No allocation; bounded time (6 bisections of ~log2(max_speed) O(log n) steps).
  [[nodiscard]] Evaluation Evaluate(const PositionEstimate& position,
                                    std::optional<std::int64_t> stop_limit_mm) const noexcept;

  // ---- helpers for the offline analysis (same integer arithmetic as Evaluate) ----------
  // v_s = v_m + ceil(v_m * speed_error_ppm / 1e6) + speed_error_abs_mm_s, at standstill too
  // (REQ-BR-007: a train creeping below the speed resolution reads 0). v_m < 0 is taken by
  // magnitude, capped at kMaxMeasuredSpeedMmS. `standstill` is accepted for interface
  // stability and does not change the result.
  [[nodiscard]] std::int64_t SupervisedSpeed(std::int64_t v_m, bool standstill = false) const noexcept;
  // Pattern speed at the supervised front y to the stop limit L (service: the stop target
  // is L - service_offset_mm). A restriction [b, e) is a ceiling for supervised fronts in
  // [b, e + length + front_error + rear_error). kNoPermittedSpeed (-1) where not even
  // standing is permitted, without a profile or with an argument out of range.
  [[nodiscard]] std::int64_t PatternSpeed(Pattern pattern, std::int64_t supervised_front_mm,
                                          std::int64_t stop_limit_mm, std::int64_t front_error_mm = 0,
                                          std::int64_t rear_error_mm = 0) const noexcept;
  [[nodiscard]] std::int64_t EmergencyPatternSpeed(std::int64_t supervised_front_mm,
                                                   std::int64_t stop_limit_mm,
                                                   std::int64_t front_error_mm = 0,
                                                   std::int64_t rear_error_mm = 0) const noexcept {
    return PatternSpeed(Pattern::kEmergency, supervised_front_mm, stop_limit_mm, front_error_mm,
                        rear_error_mm);
  }
  [[nodiscard]] std::int64_t ServicePatternSpeed(std::int64_t supervised_front_mm,
                                                 std::int64_t stop_limit_mm,
                                                 std::int64_t front_error_mm = 0,
                                                 std::int64_t rear_error_mm = 0) const noexcept {
    return PatternSpeed(Pattern::kService, supervised_front_mm, stop_limit_mm, front_error_mm,
                        rear_error_mm);
  }
  // Effective gradient for the front at y: the lowest gradient over the train (y - length, y]
  // minus gradient_error_x10 (REQ-BR-005). Without a profile: -gradient_error_x10 (level).
  [[nodiscard]] std::int64_t EffectiveGradientX10(std::int64_t front_mm) const noexcept;
  // b(y) = beta + floor(G_eff(y) * gravity / 10000) (> 0 on an accepted profile).
  [[nodiscard]] std::int64_t BrakingCapability(Pattern pattern, std::int64_t front_mm) const noexcept;
  // Worst run-up acceleration at the supervised front y: accel_max plus the accelerating
  // gravity term of the steepest falling effective gradient for fronts in
  // [y - envelope, y + d_T(max_speed)] (design note §3).
  // The true front may lie up to envelope_mm (front + rear error) behind the supervised
  // front, so the run-up window starts that far back (design note §3).
  [[nodiscard]] std::int64_t RunUpAcceleration(Pattern pattern, std::int64_t supervised_front_mm,
                                               std::int64_t envelope_mm = 0) const noexcept;
  // T = cycle_ms + reaction_ms + free-running time (maximum) of the pattern.
  [[nodiscard]] std::int64_t RunUpTimeMs(Pattern pattern) const noexcept;
  // floor(g * gravity_mm_s2 / 10000): the gravity term of gradient g, rounded away from
  // safety in both directions (design note §1).
  [[nodiscard]] std::int64_t GravityTerm(std::int64_t permille_x10) const noexcept;

  [[nodiscard]] const TrainData& train() const noexcept { return train_; }
  [[nodiscard]] const SupervisionParams& params() const noexcept { return params_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

 private:
  PatternCalculator() noexcept = default;

  // One piece of the effective-gradient profile: fronts in [start, next start).
  struct Piece {
    std::int64_t start_mm = 0;
    std::int64_t g_eff_x10 = 0;
    std::int64_t b[2] = {0, 0};       // braking capability per Pattern
    std::int64_t b2_start[2] = {0, 0};  // 2 * B(start) per Pattern
  };
  // One pattern query: pattern, stop target, ceiling extension (per Evaluate).
  struct Query {
    Pattern pattern = Pattern::kEmergency;
    std::int64_t stop_mm = 0;
    std::int64_t b2_stop = 0;
    std::int64_t ceiling_extension_mm = 0;
    std::int64_t envelope_mm = 0;  // front error + rear error: the run-up window reaches back this far
  };

  std::size_t PieceAt(std::int64_t y) const noexcept;
  std::int64_t B2(Pattern p, std::int64_t y) const noexcept;
  std::int64_t MinGradientOverPieces(std::size_t lo, std::size_t hi) const noexcept;
  std::int64_t MinLimitOverRestrictions(std::size_t lo, std::size_t hi) const noexcept;
  std::int64_t SpeedAt(const Query& q, std::int64_t y) const noexcept;
  bool BuildEffectiveGradient(std::span<const GradientSegment> gradients, std::int64_t window_mm) noexcept;

  TrainData train_{};
  SupervisionParams params_{};
  std::size_t capacity_ = 0;
  bool has_profile_ = false;
  std::int64_t run_up_ms_[2] = {0, 0};
  std::int64_t beta_[2] = {0, 0};
  std::int64_t run_up_window_mm_[2] = {0, 0};  // d_T(max_speed) at the steepest run-up acceleration

  // effective-gradient pieces (piece 0 starts at the domain minimum) and the sparse table
  // of their G_eff for range minima
  core::FixedVector<Piece> pieces_;
  core::FixedVector<std::int64_t> piece_min_g_;  // level-major sparse table
  std::size_t piece_levels_ = 0;
  // restrictions (copied), target suffix minima of V_t^2 + 2 B(begin) per Pattern, sparse
  // table of limits
  core::FixedVector<RestrictionSegment> restrictions_;
  core::FixedVector<std::int64_t> suffix_[2];
  core::FixedVector<std::int64_t> restriction_min_limit_;
  std::size_t restriction_levels_ = 0;
  // scratch of SetProfile: raw gradient pieces and the monotone deque of the window minimum
  core::FixedVector<std::int64_t> raw_start_;
  core::FixedVector<std::int64_t> raw_value_;
  core::FixedVector<std::size_t> deque_;
};

// Result of PatternCalculator::Create.
struct PatternCalculatorResult {
  CreateError error = CreateError::kNone;
  std::optional<PatternCalculator> calculator;  // engaged iff error == kNone
};

}  // namespace railproof::br
