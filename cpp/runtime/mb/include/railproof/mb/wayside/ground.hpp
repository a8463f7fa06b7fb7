// Ground (wayside) moving-block unit: train tracking, virtual-block occupancy,
// interlocking on virtual blocks (routes, points, approach locking, conflicts),
// possessions, temporary speed restrictions, handover / system-boundary handling,
// unequipped-occupancy protection and stop-limit generation
// (spec/design/mb.md §2, §3; model: ground_cycle() of models/mb.pml).
//
// Runtime module: no exceptions, no heap after Create (every container is allocated once
// by Create with the capacities of `Capacity`), no recursion, bounded loops, typed results,
// deterministic (same calls, same outputs, bit for bit).
//
// Usage (one running line, positions increasing in the running direction):
//
//   auto created = Ground::Create(line, capacity, start_ms);   // validates, allocates once
//   if (created.error != ConfigError::kNone) { ... created.entry names the entry ... }
//   Ground& g = *created.ground;
//   g.RegisterTrain({id, length_mm, front_mm, correction_mm, InitialPosition::kEntryBalise});
//   loop every ground_cycle_ms:
//     g.OnReport(report) for each received position report (any order, between cycles)
//     g.RequestRoute(...), g.RequestPossession(...), ... commands between cycles
//     g.Cycle(now_ms);                       // design §3, steps 1..5
//     for (const StopLimitTelegram& t : g.Telegrams()) send(t);
//     read outputs: g.Train(id), g.RouteSet(id), g.PointsReverse(i), g.Possession(id),
//                   g.BlockOccupied(b), g.ProtectedAuthority(id) ...
//
// Time rules (design §3): a report or registration is stamped with the time of the last
// Cycle before it (LastCycleMs(); `start_ms` before the first Cycle), never with the
// arrival time. Cycle(now) requires now >= LastCycleMs().
//
// Between cycles, commands that test "in use" (FreeRoute) use the issued-limit history as
// pruned at the last Cycle (conservative: an entry is kept until a Cycle drops it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/fixed_vector.hpp"
#include "railproof/core/track.hpp"
#include "railproof/messages/position_report.hpp"
#include "railproof/messages/stop_limit.hpp"

namespace railproof::mb::wayside {

using core::FixedVector;
using core::Overlaps;
using core::Section;
using messages::kTelegramRestrictionsMax;
using messages::Obstruction;
using messages::SpeedRestriction;
using messages::StopLimitTelegram;

// ---- line configuration -------------------------------------------------------------

// A set of points occupying one virtual block: `section` must start and end on virtual
// block boundaries. Position normal (false) or reverse (true); initially normal.
struct PointsConfig {
  std::uint32_t id;
  Section section;
};

// A route over one set of points: extent [entry_mm, exit_mm); it needs points
// `points_index` (index into LineConfig::points) in position `reverse`. Two different
// routes over the same points conflict (design §3.2). An automatic route is set by the
// ground whenever possible; while it is not set, its entry is an obstruction (ROUTE_END)
// for trains with front <= entry_mm. Non-automatic routes are set on request only.
struct RouteConfig {
  std::uint32_t id;
  std::int64_t entry_mm;
  std::int64_t exit_mm;
  std::uint32_t points_index;
  bool reverse;
  bool automatic;
};

// A radio handover point (cell boundary): an obstruction for every train for which it has
// not been secured (SecureHandover).
struct HandoverConfig {
  std::uint32_t id;
  std::int64_t position_mm;
};

// Safety margin per obstruction kind (ASM-016), mm, each >= 0.
struct Margins {
  std::int64_t preceding_train_mm;
  std::int64_t fixed_block_mm;
  std::int64_t route_end_mm;
  std::int64_t handover_mm;
  std::int64_t system_boundary_mm;
  std::int64_t possession_mm;
  std::int64_t abnormal_train_mm;
  std::int64_t end_of_track_mm;
};

// How the extended occupied range is derived from a report (design §3.6).
// @implements REQ-MB-003
// @implements REQ-MB-019
enum class MarginPolicy : std::uint8_t {
  kReportedCorrection,  // corr_r = corr_f = reported length correction
  kD2Buffers,           // corr_f = e + ceil(v tau) + l_c, corr_r = e + l_c, e = max(ceil(r(x-x_m)), corr)
};

// D2 §3.1 safety-buffer parameters (REQ-MB-019).
struct D2Params {
  std::int64_t rate_ppm;       // r, odometry error rate (1000 ppm = 0.1 %), 0 .. 1e6
  std::int64_t tau_ms;         // tau, radio delay, >= 0
  std::int64_t resolution_mm;  // l_c, >= 0
};

// The line data of one running line (REQ-MB-020). Create copies everything; the spans
// need not outlive the call. Lists of sections must be sorted by begin and must not
// overlap one another; every section lies within [0, length_mm) and is non-empty.
struct LineConfig {
  std::int64_t length_mm;                    // end of track (obstruction END_OF_TRACK)
  std::span<const std::int64_t> blocks_mm;   // virtual block boundaries: [0] = 0, strictly
                                             // increasing, back() = length_mm; block i is
                                             // [blocks_mm[i], blocks_mm[i+1])
  std::span<const Section> fixed_blocks;     // fixed-block sections (platforms, home blocks)
  std::span<const Section> setback_sections; // where backward movement is allowed (REQ-MB-005)
  std::span<const Section> no_stop_sections; // where no stop limit may fall (REQ-MB-022)
  std::span<const PointsConfig> points;      // ids unique
  std::span<const RouteConfig> routes;       // ids unique; processed in ascending id
  std::span<const HandoverConfig> handovers; // sorted by position, ids unique, inside (0, length]
  std::optional<std::int64_t> system_boundary_mm;  // inside (0, length_mm] if present
  Margins margins;
  MarginPolicy policy;
  D2Params d2;
  std::int64_t tracking_timeout_ms;    // > 0
  std::int64_t authority_validity_ms;  // > 0
  std::int64_t ground_cycle_ms;        // > 0
  std::int64_t setback_max_mm;         // >= 0
};

// Range limits that keep every int64 computation free of overflow.
inline constexpr std::int64_t kMaxLineMm = 10'000'000'000;  // 10,000 km
inline constexpr std::int64_t kMaxTimeMs = 86'400'000;      // one day

// Explicit capacities (REQ-MB-021), checked by Create; everything is allocated once.
struct Capacity {
  std::size_t trains;             // registered trains
  std::size_t blocks;             // virtual blocks (blocks_mm.size() - 1)
  std::size_t routes;
  std::size_t points;
  std::size_t sections;           // each of fixed_blocks, setback_sections, no_stop_sections
  std::size_t handovers;
  std::size_t possessions;        // requested + active possessions at a time
  std::size_t restrictions;       // requested + confirmed speed restrictions at a time
  std::size_t unequipped;         // unequipped-occupancy sections at a time
  std::size_t history_per_train;  // issued-limit history entries per train; must be
                                  // >= authority_validity_ms / ground_cycle_ms + 2
};

// Line data and capacity errors (REQ-MB-020, REQ-MB-021). Create reports the first
// violated rule, in this order, and the index of the offending entry.
// @implements REQ-MB-020
// @implements REQ-MB-021
enum class ConfigError : std::uint8_t {
  kNone,
  kLineLengthInvalid,        // length_mm <= 0 or > kMaxLineMm
  kTooFewBlocks,             // blocks_mm has fewer than 2 boundaries
  kTooManyBlocks,            // more blocks than Capacity::blocks
  kBlocksNotFromZero,        // blocks_mm[0] != 0
  kBlocksNotIncreasing,      // blocks_mm[entry] <= blocks_mm[entry-1]
  kBlocksNotToLineEnd,       // blocks_mm.back() != length_mm
  kTooManySections,          // a section list longer than Capacity::sections
  kFixedBlockInvalid,        // empty, off the line, unsorted or overlapping the previous one
  kSetBackSectionInvalid,    // idem
  kNoStopSectionInvalid,     // idem
  kTooManyPoints,
  kPointsIdDuplicate,
  kPointsSectionInvalid,     // empty or off the line
  kPointsNotOnBlockBoundaries,
  kTooManyRoutes,
  kRouteIdDuplicate,
  kRouteInvalid,             // entry >= exit, or off the line
  kRouteUnknownPoints,       // points_index >= points.size()
  kTooManyHandovers,
  kHandoverIdDuplicate,
  kHandoverInvalid,          // off (0, length_mm] or not sorted by position
  kSystemBoundaryInvalid,    // off (0, length_mm]
  kMarginInvalid,            // < 0 or > kMaxLineMm; entry: 0..7 in the order of Margins
  kPolicyInvalid,
  kD2ParamsInvalid,          // entry: 0 rate (0..1e6), 1 tau (0..kMaxTimeMs), 2 resolution (0..kMaxLineMm)
  kTimeInvalid,              // not in 1..kMaxTimeMs; entry: 0 tracking timeout, 1 validity,
                             // 2 cycle; entry 3: start_ms < 0
  kSetBackMaxInvalid,        // setback_max_mm < 0 or > kMaxLineMm
  kCapacityInvalid,          // a zero capacity where one is needed (trains, possessions,
                             // restrictions, unequipped): entry 0..3
  kHistoryTooSmall,          // history_per_train < validity / cycle + 2
  kOutOfMemory,              // allocation at Create failed
};

constexpr const char* ToString(ConfigError e) noexcept {
  return core::EnumName(e, std::array<const char*, 31>{"None", "LineLengthInvalid", "TooFewBlocks", "TooManyBlocks", "BlocksNotFromZero", "BlocksNotIncreasing", "BlocksNotToLineEnd", "TooManySections", "FixedBlockInvalid", "SetBackSectionInvalid", "NoStopSectionInvalid", "TooManyPoints", "PointsIdDuplicate", "PointsSectionInvalid", "PointsNotOnBlockBoundaries", "TooManyRoutes", "RouteIdDuplicate", "RouteInvalid", "RouteUnknownPoints", "TooManyHandovers", "HandoverIdDuplicate", "HandoverInvalid", "SystemBoundaryInvalid", "MarginInvalid", "PolicyInvalid", "D2ParamsInvalid", "TimeInvalid", "SetBackMaxInvalid", "CapacityInvalid", "HistoryTooSmall", "OutOfMemory"}, "Invalid");
}

// ---- trains and reports ---------------------------------------------------------------

// How the first position of a train became known (REQ-MB-016, D5 §5.1.7).
enum class InitialPosition : std::uint8_t {
  kStabledProvisional,  // stored stabling position sent back at restart (provisional)
  kEntryBalise,         // fixed by the balise at the entry into the radio area
};

// @implements REQ-MB-016
struct TrainRegistration {
  std::uint32_t id;
  std::int64_t length_mm;      // > 0
  std::int64_t front_mm;       // 0 .. length of line
  std::int64_t correction_mm;  // position uncertainty (>= 0), extends the range front and
                               // rear; under kD2Buffers the range is extended by
                               // correction_mm + l_c at both ends (speed 0)
  InitialPosition initial;
};

enum class RegisterStatus : std::uint8_t {
  kRegistered,
  kDuplicateId,
  kCapacityExceeded,
  kLengthInvalid,       // length <= 0 or > line length
  kFrontOffLine,        // front < 0 or > line length
  kCorrectionInvalid,   // < 0 or > line length
  kInitialInvalid,      // not an InitialPosition value
  kPositionOccupied,    // the extended range overlaps a registered train's extended range
                        // or an unequipped-occupancy section: the ground's picture would be
                        // inconsistent (report the vehicle as unequipped occupancy instead)
};

using messages::Direction;       // railproof/messages/position_report.hpp
using messages::PositionReport;  // railproof/messages/position_report.hpp

inline constexpr std::int64_t kMaxSpeedMmS = 200'000;  // 720 km/h: anything above is corrupt

// Typed rejection reasons of a position report, checked in this order (REQ-MB-001/005).
// A rejected report changes nothing.
// @implements REQ-MB-001
// @implements REQ-MB-005
enum class ReportStatus : std::uint8_t {
  kAccepted,
  kUnknownTrain,          // train_id not registered
  kBlockOutOfRange,       // front_block >= number of blocks
  kOffsetOutOfBlock,      // offset < 0 or > block length
  kLengthMismatch,        // length_mm != registered length
  kCorrectionOutOfRange,  // correction < 0 or > line length
  kBaliseOffLine,         // last_balise_mm < 0 or > line length
  kSpeedOutOfRange,       // speed < 0 or > kMaxSpeedMmS
  kWrongDirection,        // direction != kNominal
  kBackwardMovement,      // front behind the last front, outside a set-back section
  kSetBackTooFar,         // inside a set-back section but > setback_max_mm behind the
                          // furthest front reached
};

constexpr const char* ToString(ReportStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 11>{"Accepted", "UnknownTrain", "BlockOutOfRange", "OffsetOutOfBlock", "LengthMismatch", "CorrectionOutOfRange", "BaliseOffLine", "SpeedOutOfRange", "WrongDirection", "BackwardMovement", "SetBackTooFar"}, "Invalid");
}

// Front as block + offset (canonical: the block holding position front_mm - 1; block 0,
// offset 0 for front_mm = 0).
using core::BlockPosition;

// ---- commands -------------------------------------------------------------------------

enum class CommandStatus : std::uint8_t {
  kAccepted,
  kUnknownTrain,
  kUnknownRoute,
  kUnknownHandover,
  kUnknownId,           // possession / restriction / unequipped id not present
  kInvalidRange,        // empty range, off the line, or speed <= 0
  kCapacityExceeded,
  kRefusedInUse,        // FreeRoute: the route is in use (approach locking), stays set
  kNotConfirmable,      // ConfirmSpeedRestriction on an already confirmed restriction
  kNoSystemBoundary,    // AcceptAtBoundary on a line without a system boundary
};

constexpr const char* ToString(CommandStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 10>{"Accepted", "UnknownTrain", "UnknownRoute", "UnknownHandover", "UnknownId", "InvalidRange", "CapacityExceeded", "RefusedInUse", "NotConfirmable", "NoSystemBoundary"}, "Invalid");
}

// Status and the id the ground assigned (ids count up from 1; 0 on failure).
struct CommandResult {
  CommandStatus status;
  std::uint32_t id;
};

// @implements REQ-MB-014
enum class PossessionState : std::uint8_t {
  kNone,       // no such possession (never requested, or cancelled)
  kRequested,  // requested, not yet confirmed free: its start already obstructs
  kActive,     // confirmed free of trains and of authority
};

constexpr const char* ToString(PossessionState s) noexcept {
  return core::EnumName(s, std::array<const char*, 3>{"NONE", "REQUESTED", "ACTIVE"});
}

enum class CycleStatus : std::uint8_t {
  kDone,
  kClockWentBack,  // now < LastCycleMs(): nothing done, no telegram (safe side)
};

// ---- outputs --------------------------------------------------------------------------

// Per train output of the last Cycle (design §3.5).
struct TrainOutput {
  std::uint32_t train_id;
  bool abnormal;                     // tracking abnormal at the last Cycle (REQ-MB-004)
  std::optional<std::int64_t> limit_mm;  // tracked: the limit issued by the last cycle
                                         // (empty before the first cycle);
                                         // abnormal: its frozen bound (may be empty)
  Obstruction kind;                  // kind of the limit; kNone for an abnormal train
  bool provisional;                  // registered kStabledProvisional, no report accepted yet
};

// Extended occupied range [begin_mm, end_mm) (design §3.6).
struct ExtendedRange {
  std::int64_t begin_mm;
  std::int64_t end_mm;
};

// Capacity defaults: trains and blocks from spec/parameters/mb.yaml (max_trains,
// max_blocks); the history from the validity and cycle parameters.
Capacity DefaultCapacity() noexcept;

// Margins, times and D2 parameters of spec/parameters/mb.yaml; the geometry
// spans empty, length 0 (to be filled by the caller), policy kReportedCorrection.
LineConfig DefaultLineParameters() noexcept;

// @implements REQ-MB-003
// @implements REQ-MB-004
// @implements REQ-MB-006
// @implements REQ-MB-010
// @implements REQ-MB-011
// @implements REQ-MB-012
// @implements REQ-MB-013
// @implements REQ-MB-014
// @implements REQ-MB-015
// @implements REQ-MB-016
// @implements REQ-MB-017
// @implements REQ-MB-021
// @implements REQ-MB-022
// @implements REQ-MB-023
// @implements REQ-MB-024
class Ground {
 public:
  struct CreateResult {
    ConfigError error;
    std::size_t entry;               // index of the offending entry in its list (0 if n/a)
    std::unique_ptr<Ground> ground;  // non-null iff error == kNone
  };

  // Validates line + capacity (REQ-MB-020/021) and allocates all storage. The ground's
  // clock starts at start_ms (LastCycleMs() before the first Cycle).
  static CreateResult Create(const LineConfig& line, const Capacity& capacity,
                             std::int64_t start_ms = 0) noexcept;

  Ground(const Ground&) = delete;
  Ground& operator=(const Ground&) = delete;
  Ground(Ground&&) = delete;
  Ground& operator=(Ground&&) = delete;
  ~Ground();

  // -- trains --
  // Registers a train at its initial position, tracked, stamped LastCycleMs() (REQ-MB-016).
  // Checks in the order of RegisterStatus.
  RegisterStatus RegisterTrain(const TrainRegistration& registration) noexcept;
  // Removes a train (it left the area); its handover flags and history are dropped.
  CommandStatus RemoveTrain(std::uint32_t train_id) noexcept;
  // Validates and applies a position report (REQ-MB-001..005). An accepted report of an
  // abnormal train restores its tracking (its frozen bound is dropped).
  ReportStatus OnReport(const PositionReport& report) noexcept;

  // -- interlocking commands (REQ-MB-011..013) --
  // Queues a route request, processed by the next Cycle (design §3.2).
  CommandStatus RequestRoute(std::uint32_t route_id) noexcept;
  // Withdraws a pending request of the route and, if the route is set, releases it at once
  // unless it is in use (approach locking, REQ-MB-013): then kRefusedInUse, it stays set.
  CommandStatus FreeRoute(std::uint32_t route_id) noexcept;

  // -- possessions (REQ-MB-014): range [begin, end); its start obstructs from now on --
  CommandResult RequestPossession(Section range) noexcept;
  CommandStatus CancelPossession(std::uint32_t possession_id) noexcept;

  // -- radio handover, system boundary (REQ-MB-017, REQ-MB-023) --
  CommandStatus SecureHandover(std::uint32_t train_id, std::uint32_t handover_id) noexcept;
  CommandStatus AcceptAtBoundary(bool accepted) noexcept;

  // -- temporary speed restrictions (REQ-MB-015): active (sent) only once confirmed --
  CommandResult RequestSpeedRestriction(Section range, std::int64_t speed_mm_s) noexcept;
  CommandStatus ConfirmSpeedRestriction(std::uint32_t restriction_id) noexcept;
  CommandStatus CancelSpeedRestriction(std::uint32_t restriction_id) noexcept;

  // -- unequipped / failed train detected (REQ-MB-016): the section obstructs every train
  //    with front <= begin (ABNORMAL_TRAIN, margin_abnormal), counts as occupied for the
  //    virtual blocks, interlocking, possessions and fixed blocks --
  CommandResult ReportUnequippedOccupancy(Section range) noexcept;
  CommandStatus ClearUnequippedOccupancy(std::uint32_t occupancy_id) noexcept;

  // -- the ground cycle (design §3) --
  CycleStatus Cycle(std::int64_t now_ms) noexcept;

  // -- outputs --
  [[nodiscard]] std::int64_t LastCycleMs() const noexcept { return clock_ms_; }
  [[nodiscard]] std::size_t TrainCount() const noexcept { return order_.Size(); }
  // k-th train in registration order (k < TrainCount()).
  [[nodiscard]] TrainOutput TrainAt(std::size_t k) const noexcept;
  [[nodiscard]] std::optional<TrainOutput> Train(std::uint32_t train_id) const noexcept;
  // Telegrams issued by the last Cycle, one per tracked train, in registration order.
  [[nodiscard]] std::span<const StopLimitTelegram> Telegrams() const noexcept { return telegrams_.Span(); }
  // protected(t) (design §3.6): largest limit issued within the validity (as pruned at the
  // last Cycle) and, for an abnormal train, its frozen bound; empty if none / unknown train.
  [[nodiscard]] std::optional<std::int64_t> ProtectedAuthority(std::uint32_t train_id) const noexcept;
  [[nodiscard]] std::optional<ExtendedRange> Extended(std::uint32_t train_id) const noexcept;

  [[nodiscard]] bool RouteSet(std::uint32_t route_id) const noexcept;
  [[nodiscard]] bool RouteRequested(std::uint32_t route_id) const noexcept;
  [[nodiscard]] bool PointsReverse(std::size_t points_index) const noexcept;
  [[nodiscard]] PossessionState Possession(std::uint32_t possession_id) const noexcept;
  [[nodiscard]] bool RestrictionConfirmed(std::uint32_t restriction_id) const noexcept;
  [[nodiscard]] bool BoundaryAccepted() const noexcept { return boundary_accepted_; }
  [[nodiscard]] bool HandoverSecured(std::uint32_t train_id, std::uint32_t handover_id) const noexcept;

  [[nodiscard]] std::size_t BlockCount() const noexcept { return blocks_.Size() - 1; }
  // Virtual-block occupancy of the last Cycle (REQ-MB-010).
  [[nodiscard]] bool BlockOccupied(std::size_t block) const noexcept;
  // Canonical block + offset of a front position, empty if off [0, length].
  [[nodiscard]] std::optional<BlockPosition> LocateFront(std::int64_t front_mm) const noexcept;
  [[nodiscard]] std::int64_t LineLengthMm() const noexcept { return length_mm_; }

 private:
  struct HistoryEntry {
    std::int64_t limit_mm;
    std::int64_t issue_ms;
  };
  struct TrainState {
    std::uint32_t id;
    bool used;
    std::int64_t length_mm;
    std::int64_t front_mm;
    std::int64_t furthest_front_mm;
    std::int64_t corr_front_mm;
    std::int64_t corr_rear_mm;
    std::int64_t last_report_ms;
    bool abnormal;
    bool provisional;
    bool has_frozen;
    std::int64_t frozen_mm;
    std::uint32_t hist_head;   // index of the oldest entry in the ring
    std::uint32_t hist_count;
    bool has_limit;          // outputs of the last Cycle (snapshot)
    std::int64_t limit_mm;
    Obstruction kind;
    bool out_abnormal;
    // derived once per Cycle (step 1) or at each accepted report
    std::int64_t ext_begin_mm;
    std::int64_t ext_end_mm;
  };
  struct RouteState {
    RouteConfig config;
    bool set;
    bool requested;
  };
  struct PossessionEntry {
    std::uint32_t id;
    Section range;
    bool active;
  };
  struct Restriction {
    SpeedRestriction r;
    bool confirmed;
  };
  struct Unequipped {
    std::uint32_t id;
    Section range;
  };
  struct Keyed {  // sort key and slot (ties by slot: total order, deterministic)
    std::int64_t key;
    std::uint32_t slot;
  };
  struct IdSlot {
    std::uint32_t id;
    std::uint32_t slot;
  };

  Ground() noexcept = default;
  ConfigError Init(const LineConfig& line, const Capacity& capacity, std::size_t& entry) noexcept;

  [[nodiscard]] std::optional<std::uint32_t> SlotOf(std::uint32_t train_id) const noexcept;
  [[nodiscard]] std::optional<std::size_t> RouteIndex(std::uint32_t route_id) const noexcept;
  [[nodiscard]] std::optional<std::size_t> HandoverIndex(std::uint32_t handover_id) const noexcept;
  [[nodiscard]] bool SectionOnLine(const Section& s) const noexcept;

  // tracking
  void SetPosition(TrainState& t, std::int64_t front_mm, std::int64_t correction_mm,
                   std::int64_t last_balise_mm, std::int64_t speed_mm_s) noexcept;
  static void UpdateExtended(TrainState& t) noexcept;
  [[nodiscard]] bool SetBackAllowed(std::int64_t new_front, std::int64_t furthest) const noexcept;
  void PruneHistory(std::uint32_t slot, std::int64_t now_ms) noexcept;
  void AppendHistory(std::uint32_t slot, std::int64_t limit_mm, std::int64_t now_ms) noexcept;
  [[nodiscard]] std::optional<std::int64_t> Protected(std::uint32_t slot) const noexcept;
  void TrackingStep(std::int64_t now_ms) noexcept;

  // in_use(section, m) (design §3.2)
  void BuildInUseIndex() noexcept;
  [[nodiscard]] bool InUse(const Section& s, std::int64_t margin_mm) const noexcept;
  [[nodiscard]] bool InUseDirect(const Section& s, std::int64_t margin_mm) const noexcept;

  // interlocking, possessions
  void InterlockingStep() noexcept;
  [[nodiscard]] bool Conflicts(std::size_t a, std::size_t b) const noexcept;
  [[nodiscard]] bool ConflictingSet(std::size_t r) const noexcept;
  [[nodiscard]] bool ConflictingRequested(std::size_t r) const noexcept;
  void SetRoute(std::size_t r) noexcept;
  void PossessionStep() noexcept;

  // stop limits
  void BuildLimitIndex() noexcept;
  void StopLimitStep(std::int64_t now_ms) noexcept;
  [[nodiscard]] std::int64_t NoStopAdjusted(std::int64_t best, Obstruction kind) const noexcept;
  [[nodiscard]] std::int64_t MarginOf(Obstruction kind) const noexcept;
  void FillRestrictions(StopLimitTelegram& telegram, const TrainState& t) const noexcept;

  // occupancy
  void OccupancyStep() noexcept;

  // configuration
  std::int64_t length_mm_ = 0;
  FixedVector<std::int64_t> blocks_;
  FixedVector<Section> fixed_blocks_;
  FixedVector<Section> setback_;
  FixedVector<Section> no_stop_;
  FixedVector<PointsConfig> points_;
  FixedVector<RouteState> routes_;          // ascending id
  FixedVector<HandoverConfig> handovers_;   // ascending position
  FixedVector<IdSlot> handover_ids_;        // ascending id -> index in handovers_
  bool has_boundary_ = false;
  std::int64_t boundary_mm_ = 0;
  Margins margins_{};
  MarginPolicy policy_ = MarginPolicy::kReportedCorrection;
  D2Params d2_{};
  std::int64_t timeout_ms_ = 0;
  std::int64_t validity_ms_ = 0;
  std::int64_t setback_max_mm_ = 0;
  std::size_t history_cap_ = 0;

  // state
  std::int64_t clock_ms_ = 0;
  FixedVector<TrainState> trains_;          // slots (stable), size = capacity
  FixedVector<std::uint32_t> free_slots_;
  FixedVector<std::uint32_t> order_;        // registration order (slots)
  FixedVector<IdSlot> ids_;                 // ascending id
  FixedVector<HistoryEntry> history_;       // slot * history_cap_ + ring index
  FixedVector<std::uint8_t> handover_secured_;  // slot * handovers + handover index
  FixedVector<bool> points_reverse_;
  FixedVector<PossessionEntry> possessions_;     // ascending id
  FixedVector<Restriction> restrictions_;   // ascending id
  FixedVector<Unequipped> unequipped_;      // ascending id
  std::uint32_t next_possession_id_ = 1;
  std::uint32_t next_restriction_id_ = 1;
  std::uint32_t next_unequipped_id_ = 1;
  bool boundary_accepted_ = false;

  // per-cycle scratch (allocated at Create)
  FixedVector<Section> ranges_by_begin_;    // in-use index: ranges by begin, prefix max end
  FixedVector<std::int64_t> prefix_max_end_;
  FixedVector<Section> ends_;               // in-use index: {extended front end, protected}
  FixedVector<std::int64_t> prefix_max_protected_;  // by front end, prefix max protected
  FixedVector<Keyed> by_front_;             // all trains by front
  FixedVector<std::int64_t> suffix_min_rear_tracked_;
  FixedVector<std::int64_t> suffix_min_rear_abnormal_;
  FixedVector<std::uint32_t> fixed_count_;  // occupants per fixed block
  FixedVector<std::uint32_t> fixed_occupant_;  // one occupant slot (kNoSlot: unequipped)
  FixedVector<std::uint32_t> fixed_next_occupied_;
  FixedVector<std::int64_t> unset_route_entries_;  // ascending
  FixedVector<std::int64_t> possession_begins_;    // ascending
  FixedVector<std::int64_t> unequipped_begins_;    // ascending
  FixedVector<Restriction> confirmed_sorted_;      // by begin, then id
  FixedVector<std::int32_t> occupancy_diff_;
  FixedVector<std::uint8_t> occupied_;
  FixedVector<StopLimitTelegram> telegrams_;
};

}  // namespace railproof::mb::wayside
