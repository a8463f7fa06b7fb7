// Braking patterns (spec/design/br.md §1-§3).
//
// Structure (design note §3, "O(log n) envelope"):
//   SetProfile   raw gradient pieces (gaps and outside the profile: level) -> effective
//                gradient G_eff(y) = min over the train (y - length, y] - gradient_error by a
//                sliding-window minimum (monotone deque, O(n)) -> per piece the braking
//                capability b = beta + floor(G_eff * gravity / 10000) per pattern and the
//                exact integer 2B(piece start); the restriction targets' suffix minima of
//                V_t^2 + 2B(begin) per pattern; sparse tables (range minimum in O(1)) of
//                G_eff over pieces and of the limits over restrictions.
//   SpeedAt      largest integer v in [0, max_speed] with
//                  (v + ceil(a T / 1000))^2 <= min_{u in [y, z]} W_min(u),
//                  z = y + ceil(v T / 1000 + a T^2 / 2e6),
//                found by bisection; each check costs O(log n) (binary searches + O(1) range
//                minima).
//
// Deviation from the letter of the note (safe side, recorded in the report): the note
// writes W_min(y + d_T(v)); this code uses the minimum of W_min over the whole run-up
// [y, y + d_T(v)]. The two are equal wherever W_min is non-increasing; they differ only when
// a restriction ceiling ends inside the run-up, where W_min(y + d_T) would let a high speed
// "jump over" the rest of the ceiling and where the predicate would not be monotone in v
// (bisection would be unsound). With the minimum over the run-up the predicate is monotone
// and every ceiling touched during the run-up is respected.
//
// Magnitudes (all int64, no overflow with the ranges of patterns.hpp): positions within
// +-1.1e10 mm (inputs +-1e10, errors 1e7, run-up and leads < 6e8) against the domain origin
// -4e10; b <= 2.2e4 mm/s^2, so 2B <= 2 * 2.2e4 * 6e10 < 3e15; speeds <= 2.1e6 mm/s, run-up
// speed gain ceil(a T / 1000) <= 2.2e4 * 1.8e5 / 1e3 < 4e6, so (v + dv)^2 < 4e13;
// 2000 v T + a T^2 < 2e3 * 1e6 * 1.8e5 + 2.2e4 * 3.3e10 < 1.1e15.
//
// Seeded faults (negative tests, cpp/runtime/br/tests/test_patterns.cpp kills each one):
// FAULT_BR_NO_FREE_RUNNING, FAULT_BR_GRADIENT_FRONT_ONLY, FAULT_BR_RESTRICTION_FRONT_RELEASE,
// FAULT_BR_NO_SPEED_ALLOWANCE; active only in the test-only schemata variant
// (spec/design/seeded-faults.md).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/br/patterns.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <utility>

namespace railproof::br {
namespace {

constexpr std::int64_t kDomainMinMm = -4 * kMaxPositionMm;
constexpr std::int64_t kPlusInf = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kPpm = 1'000'000;
constexpr std::int64_t kMsPerS = 1'000;
constexpr std::int64_t kGradientScale = 10'000;  // permille x 10 -> fraction
constexpr std::size_t kE = 0;                    // index of Pattern::kEmergency
constexpr std::size_t kN = 1;                    // index of Pattern::kService

constexpr std::size_t Index(Pattern p) noexcept { return p == Pattern::kEmergency ? kE : kN; }

// ceil(a / b) for a >= 0, b > 0.
constexpr std::int64_t CeilDiv(std::int64_t a, std::int64_t b) noexcept { return (a + b - 1) / b; }

// floor(a / b) for b > 0.
constexpr std::int64_t FloorDiv(std::int64_t a, std::int64_t b) noexcept {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

constexpr bool InRange(std::int64_t v, std::int64_t lo, std::int64_t hi) noexcept {
  return v >= lo && v <= hi;
}

// Run-up distance d_T(v) = ceil(v T / 1000 + a T^2 / 2e6) (rounded up: run distance).
constexpr std::int64_t RunUpDistance(std::int64_t v, std::int64_t a, std::int64_t t_ms) noexcept {
  return CeilDiv(2 * kMsPerS * v * t_ms + a * t_ms * t_ms, 2 * kMsPerS * kMsPerS);
}

// Levels of a sparse table over n >= 1 values.
constexpr std::size_t Levels(std::size_t n) noexcept {
  return n == 0 ? 1 : static_cast<std::size_t>(std::bit_width(n));
}

// Fills levels 1.. of a level-major sparse table (stride = width) whose level 0 holds n values.
void BuildSparseTable(core::FixedVector<std::int64_t>& t, std::size_t stride, std::size_t n,
                      std::size_t levels) noexcept {
  for (std::size_t lev = 1; lev < levels; ++lev) {
    const std::size_t half = std::size_t{1} << (lev - 1);
    const std::size_t span = half << 1;
    for (std::size_t k = 0; k + span <= n; ++k) {
      t[lev * stride + k] =
          std::min(t[(lev - 1) * stride + k], t[(lev - 1) * stride + k + half]);
    }
  }
}

// Range minimum over [lo, hi] (lo <= hi < n) of a sparse table.
std::int64_t QuerySparseTable(const core::FixedVector<std::int64_t>& t, std::size_t stride,
                              std::size_t lo, std::size_t hi) noexcept {
  const std::size_t len = hi - lo + 1;
  const auto lev = static_cast<std::size_t>(std::bit_width(len) - 1);
  return std::min(t[lev * stride + lo], t[lev * stride + hi + 1 - (std::size_t{1} << lev)]);
}

// First restriction index j with begin_mm > x (restrictions sorted by begin).
std::size_t FirstBeginAfter(std::span<const RestrictionSegment> r, std::int64_t x) noexcept {
  std::size_t lo = 0;
  std::size_t hi = r.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (r[mid].begin_mm <= x) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// First restriction index j with end_mm + extension > y (ends sorted as the restrictions
// are sorted and do not overlap).
std::size_t FirstEndAfter(std::span<const RestrictionSegment> r, std::int64_t y,
                          std::int64_t extension) noexcept {
  std::size_t lo = 0;
  std::size_t hi = r.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (r[mid].end_mm + extension <= y) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// The ceiling of a restriction lasts for supervised fronts below end + extension: the rear
// x_m - length - e_r is before the end iff x_s = x_m + e_f < end + length + e_r + e_f
// (REQ-BR-004).
// @implements REQ-BR-004
std::int64_t CeilingExtension(const TrainData& train, std::int64_t front_error_mm,
                              std::int64_t rear_error_mm) noexcept {
  if (RAILPROOF_FAULT(FAULT_BR_RESTRICTION_FRONT_RELEASE)) {
    return 0;
  }
  return train.length_mm + front_error_mm + rear_error_mm;
}

// Length of the window over which the effective gradient takes the lowest gradient
// (REQ-BR-005): the train length.
// @implements REQ-BR-005
std::int64_t GradientWindow(const TrainData& train) noexcept {
  return RAILPROOF_FAULT(FAULT_BR_GRADIENT_FRONT_ONLY) ? 0 : train.length_mm;
}

// T = cycle + reaction + free-running time (REQ-BR-001, REQ-BR-002).
// @implements REQ-BR-001 REQ-BR-002
std::int64_t RunUpTime(const SupervisionParams& p, std::int64_t free_running_ms) noexcept {
  if (RAILPROOF_FAULT(FAULT_BR_NO_FREE_RUNNING)) {
    return p.cycle_ms + p.reaction_ms;
  }
  return p.cycle_ms + p.reaction_ms + free_running_ms;
}

CreateError ValidateTrain(const TrainData& t) noexcept {
  if (!InRange(t.length_mm, 1, kMaxTrainLengthMm)) {
    return CreateError::kTrainLengthInvalid;
  }
  if (!InRange(t.accel_max_mm_s2, 0, kMaxAccelerationMmS2)) {
    return CreateError::kAccelerationInvalid;
  }
  if (!InRange(t.beta_e_mm_s2, 1, kMaxAccelerationMmS2) ||
      !InRange(t.beta_n7_mm_s2, 1, kMaxAccelerationMmS2)) {
    return CreateError::kDecelerationInvalid;
  }
  if (t.beta_n7_mm_s2 > t.beta_e_mm_s2) {
    return CreateError::kServiceAboveEmergency;
  }
  if (!InRange(t.emergency_free_running_ms, 0, kMaxTimeMs) ||
      !InRange(t.service_free_running_ms, 0, kMaxTimeMs)) {
    return CreateError::kFreeRunningInvalid;
  }
  if (!InRange(t.overspeed_mm_s, 0, kMaxSpeedAllowanceMmS) ||
      !InRange(t.speed_error_abs_mm_s, 0, kMaxSpeedAllowanceMmS) ||
      !InRange(t.speed_error_ppm, 0, kPpm)) {
    return CreateError::kSpeedAllowanceInvalid;
  }
  return CreateError::kNone;
}

CreateError ValidateParams(const SupervisionParams& p) noexcept {
  if (!InRange(p.cycle_ms, 1, kMaxTimeMs) || !InRange(p.reaction_ms, 0, kMaxTimeMs)) {
    return CreateError::kTimeInvalid;
  }
  if (!InRange(p.service_offset_mm, 0, kMaxPositionErrorMm)) {
    return CreateError::kServiceOffsetInvalid;
  }
  if (!(p.lead_6n_ms > 0 && p.lead_6n_ms < p.lead_5n_ms && p.lead_5n_ms < p.lead_4n_ms &&
        p.lead_4n_ms < p.release_lead_ms && p.release_lead_ms <= kMaxTimeMs)) {
    return CreateError::kLeadsInvalid;
  }
  if (!InRange(p.gradient_error_x10, 0, kMaxGradientX10)) {
    return CreateError::kGradientErrorInvalid;
  }
  if (!InRange(p.gravity_mm_s2, 1, kMaxAccelerationMmS2)) {
    return CreateError::kGravityInvalid;
  }
  if (!InRange(p.max_speed_mm_s, 1, kMaxLimitMmS)) {
    return CreateError::kMaxSpeedInvalid;
  }
  return CreateError::kNone;
}

// Common segment checks of both lists (position range, empty, order, overlap).
template <typename Segment>
ProfileVerdict CheckSegment(std::span<const Segment> list, std::size_t i) noexcept {
  const Segment& s = list[i];
  if (!InRange(s.begin_mm, -kMaxPositionMm, kMaxPositionMm) ||
      !InRange(s.end_mm, -kMaxPositionMm, kMaxPositionMm)) {
    return ProfileVerdict::kPositionOutOfRange;
  }
  if (s.begin_mm >= s.end_mm) {
    return ProfileVerdict::kEmptySegment;
  }
  if (i > 0 && s.begin_mm < list[i - 1].begin_mm) {
    return ProfileVerdict::kUnsorted;
  }
  if (i > 0 && s.begin_mm < list[i - 1].end_mm) {
    return ProfileVerdict::kOverlap;
  }
  return ProfileVerdict::kAccept;
}

}  // namespace

SupervisionParams DefaultSupervisionParams() noexcept {
  namespace p = params::br;
  SupervisionParams s;
  s.cycle_ms = p::cycle_ms;
  s.reaction_ms = p::reaction_ms;
  s.service_offset_mm = p::service_offset_mm;
  s.lead_4n_ms = p::lead_4n_ms;
  s.lead_5n_ms = p::lead_5n_ms;
  s.lead_6n_ms = p::lead_6n_ms;
  s.release_lead_ms = p::release_lead_ms;
  s.gradient_error_x10 = p::gradient_error_x10;
  s.gravity_mm_s2 = p::gravity_mm_s2;
  s.max_speed_mm_s = p::max_speed_mm_s;
  return s;
}

// @implements REQ-BR-008 REQ-BR-010
PatternCalculator::CreateResult PatternCalculator::Create(const TrainData& train,
                                                          const SupervisionParams& params,
                                                          std::size_t capacity) noexcept {
  CreateResult result;
  result.error = ValidateTrain(train);
  if (result.error == CreateError::kNone) {
    result.error = ValidateParams(params);
  }
  if (result.error == CreateError::kNone && (capacity == 0 || capacity > kMaxProfileCapacity)) {
    result.error = CreateError::kCapacityInvalid;
  }
  if (result.error != CreateError::kNone) {
    return result;
  }
  PatternCalculator c;
  c.train_ = train;
  c.params_ = params;
  c.capacity_ = capacity;
  c.beta_[kE] = train.beta_e_mm_s2;
  c.beta_[kN] = train.beta_n7_mm_s2;
  c.run_up_ms_[kE] = RunUpTime(params, train.emergency_free_running_ms);
  c.run_up_ms_[kN] = RunUpTime(params, train.service_free_running_ms);
  // raw pieces: a level gap before every segment, the segment, the level after the last
  const std::size_t raw = 2 * capacity + 1;
  // effective pieces: one per entry or exit event of a raw piece, plus the first
  const std::size_t pieces = 2 * raw;
  c.piece_levels_ = Levels(pieces);
  c.restriction_levels_ = Levels(capacity);
  const bool ok = c.pieces_.Allocate(pieces) && c.piece_min_g_.Allocate(pieces * c.piece_levels_) &&
                  c.piece_min_g_.Resize(pieces * c.piece_levels_) &&
                  c.restrictions_.Allocate(capacity) && c.suffix_[kE].Allocate(capacity) &&
                  c.suffix_[kE].Resize(capacity) && c.suffix_[kN].Allocate(capacity) &&
                  c.suffix_[kN].Resize(capacity) &&
                  c.restriction_min_limit_.Allocate(capacity * c.restriction_levels_) &&
                  c.restriction_min_limit_.Resize(capacity * c.restriction_levels_) &&
                  c.raw_start_.Allocate(raw) && c.raw_value_.Allocate(raw) &&
                  c.deque_.Allocate(raw) && c.deque_.Resize(raw);
  if (!ok) {
    result.error = CreateError::kOutOfMemory;  // GCOVR_EXCL_LINE defensive: out of memory
    return result;                             // GCOVR_EXCL_LINE
  }
  result.calculator.emplace(std::move(c));
  return result;
}

std::int64_t PatternCalculator::GravityTerm(std::int64_t permille_x10) const noexcept {
  return FloorDiv(permille_x10 * params_.gravity_mm_s2, kGradientScale);
}

std::int64_t PatternCalculator::RunUpTimeMs(Pattern pattern) const noexcept {
  return run_up_ms_[Index(pattern)];
}

// Effective gradient pieces by a sliding-window minimum over the raw pieces: raw piece i
// (fronts' gradient on [start_i, start_{i+1})) is under the train for fronts in
// [start_i, start_{i+1} + window). Entries and exits are both sorted, so one merge pass
// with a monotone deque (indices of increasing value) gives every piece in O(n).
// @implements REQ-BR-005
bool PatternCalculator::BuildEffectiveGradient(std::span<const GradientSegment> gradients,
                                               std::int64_t window_mm) noexcept {
  raw_start_.Clear();
  raw_value_.Clear();
  std::int64_t cursor = kDomainMinMm;
  bool ok = true;
  for (const GradientSegment& g : gradients) {
    if (g.begin_mm > cursor) {
      ok = ok && raw_start_.PushBack(cursor) && raw_value_.PushBack(0);
    }
    ok = ok && raw_start_.PushBack(g.begin_mm) && raw_value_.PushBack(g.permille_x10);
    cursor = g.end_mm;
  }
  ok = ok && raw_start_.PushBack(cursor) && raw_value_.PushBack(0);
  if (!ok) {
    return false;  // GCOVR_EXCL_LINE defensive: capacity checked by SetProfile
  }
  const std::size_t m = raw_start_.Size();
  pieces_.Clear();
  std::size_t head = 0;
  std::size_t tail = 0;
  std::size_t next_enter = 0;
  std::size_t next_exit = 0;
  // Every iteration consumes at least one of the 2m - 1 entry / exit events.
  for (std::size_t iter = 0; iter < 2 * m; ++iter) {
    std::int64_t p = kPlusInf;
    if (next_enter < m) {
      p = raw_start_[next_enter];
    }
    if (next_exit + 1 < m) {
      p = std::min(p, raw_start_[next_exit + 1] + window_mm);
    }
    if (p == kPlusInf) {
      break;
    }
    while (next_enter < m && raw_start_[next_enter] <= p) {
      const std::int64_t v = raw_value_[next_enter];
      while (tail > head && raw_value_[deque_[tail - 1]] >= v) {
        --tail;
      }
      deque_[tail] = next_enter;
      ++tail;
      ++next_enter;
    }
    while (next_exit + 1 < m && raw_start_[next_exit + 1] + window_mm <= p) {
      ++next_exit;
    }
    while (head < tail && deque_[head] < next_exit) {
      ++head;
    }
    // The last entered piece (index >= next_exit) is always in the deque.
    const std::int64_t g_eff = raw_value_[deque_[head]] - params_.gradient_error_x10;
    if (pieces_.Empty() || pieces_[pieces_.Size() - 1].g_eff_x10 != g_eff) {
      Piece piece;
      piece.start_mm = p;
      piece.g_eff_x10 = g_eff;
      if (!pieces_.PushBack(piece)) {
        return false;  // GCOVR_EXCL_LINE defensive: at most 2m pieces, capacity 2 (2n + 1)
      }
    }
  }
  return true;
}

// @implements REQ-BR-005 REQ-BR-008
ProfileResult PatternCalculator::SetProfile(std::span<const GradientSegment> gradients,
                                            std::span<const RestrictionSegment> restrictions) noexcept {
  has_profile_ = false;
  ProfileResult result;
  if (gradients.size() > capacity_) {
    result.verdict = ProfileVerdict::kTooManyGradients;
    return result;
  }
  if (restrictions.size() > capacity_) {
    result.verdict = ProfileVerdict::kTooManyRestrictions;
    result.in_restrictions = true;
    return result;
  }
  std::int64_t min_gradient = 0;  // the level outside the profile is always present
  std::size_t min_entry = 0;
  for (std::size_t i = 0; i < gradients.size(); ++i) {
    ProfileVerdict v = CheckSegment(gradients, i);
    if (v == ProfileVerdict::kAccept && !InRange(gradients[i].permille_x10, -kMaxGradientX10, kMaxGradientX10)) {
      v = ProfileVerdict::kGradientOutOfRange;
    }
    if (v != ProfileVerdict::kAccept) {
      result.verdict = v;
      result.entry = i;
      return result;
    }
    if (gradients[i].permille_x10 < min_gradient) {
      min_gradient = gradients[i].permille_x10;
      min_entry = i;
    }
  }
  for (std::size_t i = 0; i < restrictions.size(); ++i) {
    ProfileVerdict v = CheckSegment(restrictions, i);
    if (v == ProfileVerdict::kAccept && !InRange(restrictions[i].limit_mm_s, 1, kMaxLimitMmS)) {
      v = ProfileVerdict::kLimitOutOfRange;
    }
    if (v != ProfileVerdict::kAccept) {
      result.verdict = v;
      result.in_restrictions = true;
      result.entry = i;
      return result;
    }
  }
  // Every effective gradient is a raw gradient (or the level 0) minus the data error, so
  // the lowest braking capability is that of min(0, min gradient) - error.
  const std::int64_t worst_grav = GravityTerm(min_gradient - params_.gradient_error_x10);
  if (beta_[kE] + worst_grav <= 0 || beta_[kN] + worst_grav <= 0) {
    result.verdict = ProfileVerdict::kBrakingNotPositive;
    result.entry = min_entry;
    return result;
  }

  if (!BuildEffectiveGradient(gradients, GradientWindow(train_))) {
    result.verdict = ProfileVerdict::kTooManyGradients;  // GCOVR_EXCL_LINE defensive
    return result;                                      // GCOVR_EXCL_LINE
  }
  // braking capability and exact integral 2B per piece; G_eff sparse table level 0
  const std::size_t n_pieces = pieces_.Size();
  const std::size_t stride = pieces_.Capacity();
  std::int64_t acc[2] = {0, 0};
  for (std::size_t k = 0; k < n_pieces; ++k) {
    Piece& piece = pieces_[k];
    const std::int64_t grav = GravityTerm(piece.g_eff_x10);
    for (std::size_t p = 0; p < 2; ++p) {
      piece.b[p] = beta_[p] + grav;
      piece.b2_start[p] = acc[p];
      if (k + 1 < n_pieces) {
        acc[p] += 2 * piece.b[p] * (pieces_[k + 1].start_mm - piece.start_mm);
      }
    }
    piece_min_g_[k] = piece.g_eff_x10;
  }
  BuildSparseTable(piece_min_g_, stride, n_pieces, Levels(n_pieces));
  restrictions_.Clear();
  for (const RestrictionSegment& r : restrictions) {
    (void)restrictions_.PushBack(r);  // fits: size checked above
  }
  // suffix minima of V_t^2 + 2B(begin) (the target curves ahead) and the limit table
  const std::size_t n_r = restrictions_.Size();
  for (std::size_t i = n_r; i-- > 0;) {
    const RestrictionSegment& r = restrictions_[i];
    for (std::size_t p = 0; p < 2; ++p) {
      const std::int64_t v = r.limit_mm_s + (p == kE ? train_.overspeed_mm_s : 0);
      const std::int64_t term = v * v + B2(p == kE ? Pattern::kEmergency : Pattern::kService, r.begin_mm);
      suffix_[p][i] = (i + 1 < n_r) ? std::min(term, suffix_[p][i + 1]) : term;
    }
    restriction_min_limit_[i] = r.limit_mm_s;
  }
  if (n_r > 0) {
    BuildSparseTable(restriction_min_limit_, capacity_, n_r, Levels(n_r));
  }
  // run-up windows: d_T(max_speed) at the steepest run-up acceleration anywhere
  const std::int64_t g_min = MinGradientOverPieces(0, n_pieces - 1);
  const std::int64_t a_bound = train_.accel_max_mm_s2 + std::max<std::int64_t>(0, -GravityTerm(g_min));
  for (std::size_t p = 0; p < 2; ++p) {
    run_up_window_mm_[p] = RunUpDistance(params_.max_speed_mm_s, a_bound, run_up_ms_[p]);
  }
  has_profile_ = true;
  return result;
}

std::size_t PatternCalculator::PieceAt(std::int64_t y) const noexcept {
  // last k with start <= y (piece 0 starts at the domain minimum, below every position)
  std::size_t lo = 0;
  std::size_t hi = pieces_.Size();
  while (hi - lo > 1) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (pieces_[mid].start_mm <= y) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

std::int64_t PatternCalculator::B2(Pattern pattern, std::int64_t y) const noexcept {
  const Piece& piece = pieces_[PieceAt(y)];
  const std::size_t p = Index(pattern);
  return piece.b2_start[p] + 2 * piece.b[p] * (y - piece.start_mm);
}

std::int64_t PatternCalculator::MinGradientOverPieces(std::size_t lo, std::size_t hi) const noexcept {
  return QuerySparseTable(piece_min_g_, pieces_.Capacity(), lo, hi);
}

std::int64_t PatternCalculator::MinLimitOverRestrictions(std::size_t lo, std::size_t hi) const noexcept {
  return QuerySparseTable(restriction_min_limit_, capacity_, lo, hi);
}

std::int64_t PatternCalculator::EffectiveGradientX10(std::int64_t front_mm) const noexcept {
  if (!has_profile_) {
    return -params_.gradient_error_x10;
  }
  return pieces_[PieceAt(front_mm)].g_eff_x10;
}

std::int64_t PatternCalculator::BrakingCapability(Pattern pattern, std::int64_t front_mm) const noexcept {
  return beta_[Index(pattern)] + GravityTerm(EffectiveGradientX10(front_mm));
}

// @implements REQ-BR-005
std::int64_t PatternCalculator::RunUpAcceleration(Pattern pattern, std::int64_t supervised_front_mm,
                                                  std::int64_t envelope_mm) const noexcept {
  std::int64_t g = -params_.gradient_error_x10;
  if (has_profile_) {
    const std::size_t lo = PieceAt(supervised_front_mm - envelope_mm);
    const std::size_t hi = PieceAt(supervised_front_mm + run_up_window_mm_[Index(pattern)]);
    g = MinGradientOverPieces(lo, hi);
  }
  return train_.accel_max_mm_s2 + std::max<std::int64_t>(0, -GravityTerm(g));
}

// Pattern speed at y (design note §3): bisection on the monotone predicate.
// @implements REQ-BR-001 REQ-BR-002 REQ-BR-004 REQ-BR-008
std::int64_t PatternCalculator::SpeedAt(const Query& q, std::int64_t y) const noexcept {
  const std::size_t p = Index(q.pattern);
  const std::int64_t a = RunUpAcceleration(q.pattern, y, q.envelope_mm);
  const std::int64_t t = run_up_ms_[p];
  const std::int64_t dv = CeilDiv(a * t, kMsPerS);
  const std::int64_t overspeed = q.pattern == Pattern::kEmergency ? train_.overspeed_mm_s : 0;
  const std::span<const RestrictionSegment> r = restrictions_.Span();
  // restrictions whose ceiling lasts beyond y (index >= first_ceiling)
  const std::size_t first_ceiling = FirstEndAfter(r, y, q.ceiling_extension_mm);
  auto passes = [&](std::int64_t v) noexcept {
    const std::int64_t z = y + RunUpDistance(v, a, t);
    if (z >= q.stop_mm) {
      return false;  // nothing permitted at or beyond the stop target
    }
    const std::int64_t b2z = B2(q.pattern, z);
    std::int64_t w = q.b2_stop - b2z;
    const std::size_t ahead = FirstBeginAfter(r, z);
    if (ahead < r.size()) {
      w = std::min(w, suffix_[p][ahead] - b2z);
    }
    if (first_ceiling < ahead) {  // ceilings met during the run-up [y, z]
      const std::int64_t ceiling = MinLimitOverRestrictions(first_ceiling, ahead - 1) + overspeed;
      w = std::min(w, ceiling * ceiling);
    }
    const std::int64_t u = v + dv;
    return u * u <= w;
  };
  if (!passes(0)) {
    return kNoPermittedSpeed;  // not even standing is permitted: hold the brake
  }
  std::int64_t lo = 0;                        // passes
  std::int64_t hi = params_.max_speed_mm_s;   // candidate
  if (passes(hi)) {
    return hi;
  }
  // invariant: passes(lo), !passes(hi); at most log2(max_speed) + 1 iterations
  while (hi - lo > 1) {
    const std::int64_t mid = lo + (hi - lo) / 2;
    if (passes(mid)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// @implements REQ-BR-007
std::int64_t PatternCalculator::SupervisedSpeed(std::int64_t v_m, bool standstill) const noexcept {
  std::int64_t v = v_m;
  if (v < 0) {
    v = v < -kMaxMeasuredSpeedMmS ? kMaxMeasuredSpeedMmS : -v;
  }
  v = std::min(v, kMaxMeasuredSpeedMmS);
  // The allowance is added at standstill too: a train creeping below the speed resolution
  // reads 0 (and may even report standstill) while its true speed is up to the allowance.
  (void)standstill;
  if (RAILPROOF_FAULT(FAULT_BR_NO_SPEED_ALLOWANCE)) {
    return v;
  }
  return v + CeilDiv(v * train_.speed_error_ppm, kPpm) + train_.speed_error_abs_mm_s;
}

// @implements REQ-BR-001 REQ-BR-002 REQ-BR-004
std::int64_t PatternCalculator::PatternSpeed(Pattern pattern, std::int64_t supervised_front_mm,
                                             std::int64_t stop_limit_mm, std::int64_t front_error_mm,
                                             std::int64_t rear_error_mm) const noexcept {
  const bool valid = has_profile_ &&
                     InRange(supervised_front_mm, -kMaxPositionMm - kMaxPositionErrorMm,
                             kMaxPositionMm + kMaxPositionErrorMm) &&
                     InRange(stop_limit_mm, -kMaxPositionMm, kMaxPositionMm) &&
                     InRange(front_error_mm, 0, kMaxPositionErrorMm) &&
                     InRange(rear_error_mm, 0, kMaxPositionErrorMm);
  if (!valid) {
    return kNoPermittedSpeed;
  }
  Query q;
  q.pattern = pattern;
  q.stop_mm = pattern == Pattern::kEmergency ? stop_limit_mm : stop_limit_mm - params_.service_offset_mm;
  q.b2_stop = B2(pattern, q.stop_mm);
  q.ceiling_extension_mm = CeilingExtension(train_, front_error_mm, rear_error_mm);
  q.envelope_mm = front_error_mm + rear_error_mm;
  return SpeedAt(q, supervised_front_mm);
}

// @implements REQ-BR-001 REQ-BR-002 REQ-BR-003 REQ-BR-004 REQ-BR-007 REQ-BR-008 REQ-BR-012 REQ-BR-014
Evaluation PatternCalculator::Evaluate(const PositionEstimate& position,
                                       std::optional<std::int64_t> stop_limit_mm) const noexcept {
  Evaluation out;
  out.status = EvalStatus::kOk;
  if (!has_profile_) {
    out.status = EvalStatus::kNoProfile;
  } else if (!InRange(position.front_mm, -kMaxPositionMm, kMaxPositionMm) ||
             !InRange(position.front_error_mm, 0, kMaxPositionErrorMm) ||
             !InRange(position.rear_error_mm, 0, kMaxPositionErrorMm)) {
    out.status = EvalStatus::kInvalidPosition;
  } else if (!InRange(position.speed_mm_s, 0, kMaxMeasuredSpeedMmS)) {
    out.status = EvalStatus::kInvalidSpeed;
  } else if (stop_limit_mm.has_value() && !InRange(*stop_limit_mm, -kMaxPositionMm, kMaxPositionMm)) {
    out.status = EvalStatus::kInvalidStopLimit;
  }
  const std::int64_t v_s = SupervisedSpeed(position.speed_mm_s, position.standstill);
  if (out.status != EvalStatus::kOk) {
    // fail-safe: no speed permitted, so the emergency brake is commanded (and held)
    out.speeds = PatternSpeeds{v_s, kNoPermittedSpeed, kNoPermittedSpeed, kNoPermittedSpeed,
                               kNoPermittedSpeed, kNoPermittedSpeed, kNoPermittedSpeed};
    return out;
  }
  out.speeds.v_s = v_s;
  const std::int64_t x_s = position.front_mm + position.front_error_mm;
  // REQ-BR-012: without a usable stop limit, the stop limit is the supervised front.
  const std::int64_t limit = stop_limit_mm.value_or(x_s);
  const std::int64_t extension = CeilingExtension(train_, position.front_error_mm, position.rear_error_mm);
  Query qe;
  qe.pattern = Pattern::kEmergency;
  qe.stop_mm = limit;
  qe.b2_stop = B2(Pattern::kEmergency, limit);
  qe.ceiling_extension_mm = extension;
  qe.envelope_mm = position.front_error_mm + position.rear_error_mm;
  Query qn;
  qn.pattern = Pattern::kService;
  qn.stop_mm = limit - params_.service_offset_mm;
  qn.b2_stop = B2(Pattern::kService, qn.stop_mm);
  qn.ceiling_extension_mm = extension;
  qn.envelope_mm = qe.envelope_mm;
  auto lead_point = [&](std::int64_t lead_ms) noexcept { return x_s + CeilDiv(v_s * lead_ms, kMsPerS); };
  out.speeds.v_e = SpeedAt(qe, x_s);
  out.speeds.v_7n = SpeedAt(qn, x_s);
  out.speeds.v_6n = SpeedAt(qn, lead_point(params_.lead_6n_ms));
  out.speeds.v_5n = SpeedAt(qn, lead_point(params_.lead_5n_ms));
  out.speeds.v_4n = SpeedAt(qn, lead_point(params_.lead_4n_ms));
  out.speeds.v_release = SpeedAt(qn, lead_point(params_.release_lead_ms));
  return out;
}

}  // namespace railproof::br
