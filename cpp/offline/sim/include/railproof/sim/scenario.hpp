// Scenario files of the line simulation (spec/scenarios/*.json, format in
// spec/scenarios/README.md, schema spec/schemas/scenario.schema.json). Offline module:
// LoadScenario throws InputError with a one-line message naming the file and the entry.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::sim {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

inline constexpr std::string_view kScenarioSchema = "railproof/scenario/1";

struct StopSpec {
  std::string station;
  std::int64_t dwell_ms = 0;
};

struct TrainSpec {
  std::uint16_t id = 0;  // radio address of the on-board unit; never the ground's id
  TrainPerformance performance;
  std::int64_t initial_front_mm = 0;
  std::int64_t enter_ms = 0;   // registered with the ground (entry balise) at this time
  std::int64_t depart_ms = 0;  // leaves its initial position at this time (>= enter_ms)
  std::vector<StopSpec> stops;
  std::optional<double> speed_cap_mps;  // e.g. a leader limited to 20 km/h
  std::optional<std::string> train_type;  // the spec/trains type the on-board unit carries
  std::string entry;                    // path in the file, for messages ("trains[1]")
};

enum class FaultType : std::uint8_t {
  kRadioLoss,      // both directions of one train's radio link lost in [from, to)
  kTrackingLoss,   // the on-board unit loses its position: no reports in [from, to), brakes to a stop
  kPossession,     // possession of [begin, end) requested at from, cancelled at to
  kSidingRequest,  // the siding (reverse) route requested at from, freed at to
  kSpeedRestriction,  // temporary speed restriction on [begin, end) requested and confirmed
                      // at from, cancelled at to (not a fault: an operating event)
};

const char* ToString(FaultType type);

struct FaultSpec {
  FaultType type = FaultType::kRadioLoss;
  std::optional<std::uint16_t> train;  // radio_loss, tracking_loss
  std::int64_t begin_mm = 0;           // possession, speed_restriction
  std::int64_t end_mm = 0;             // possession, speed_restriction
  std::int64_t route = 0;              // siding_request (0: not given)
  double speed_mps = 0.0;              // speed_restriction
  std::int64_t from_ms = 0;
  std::int64_t to_ms = 0;
  std::string entry;
};

struct ChannelSpec {
  double loss_probability = 0.0;     // each telegram independently, seeded PRNG
  std::int64_t min_delay_ms = 0;     // delay uniform in [min, max]
  std::int64_t max_delay_ms = 0;
  double corrupt_probability = 0.0;  // a telegram gets 1..12 symbol errors in one RS block
};

// Gap measurement between a leader and its follower (the D5 field-test reproduction).
struct GapSpec {
  std::uint16_t leader = 0;
  std::uint16_t follower = 0;
  std::int64_t from_ms = 0;  // averaging window
  std::int64_t to_ms = 0;
};

enum class MarginPolicy : std::uint8_t { kReported, kD2 };

// A split of the running line between two wayside units (spec/design/sim.md): the unit before
// has its system boundary at at_mm and its line runs overlap_mm past it; the next unit's line
// begins overlap_mm before it (the handover zone).
struct WaysideSplit {
  std::int64_t at_mm = 0;
  std::int64_t overlap_mm = 0;
  std::string entry;  // "wayside_splits[i]"
};

// A section of reduced adhesion (wet rail, leaves): the rail's adhesion in [begin, end) is the
// dry rail's times the wet rail's factor (wet) times `factor`. The trains that run on the
// wheel-rail vehicle (spec/design/sim.md) feel it; a point-mass train rolls on dry rail.
struct AdhesionSectionSpec {
  std::int64_t begin_mm = 0;
  std::int64_t end_mm = 0;
  bool wet = true;
  double factor = 1.0;  // (0, 1]
  std::string entry;
};

struct Scenario {
  std::string file;
  std::string name;
  std::string description;
  std::string line;          // line name: <lines-dir>/<line>.json
  std::string running_line;  // e.g. "up"
  std::int64_t duration_ms = 0;
  std::int64_t step_ms = 100;
  std::uint64_t seed = 1;
  std::int64_t ground_cycle_ms = 0;   // default: parameter ground_cycle_ms
  std::int64_t report_period_ms = 0;  // default: parameter report_period_ms
  MarginPolicy margin_policy = MarginPolicy::kReported;
  ChannelSpec channel;
  std::int64_t sample_ms = 1000;  // diagram / time series resolution
  double handover_secure_ahead_m = 2000.0;  // radio channel secured this far ahead of a train
  bool boundary_accepted = true;            // the neighbour accepts trains at the system boundary
  std::vector<WaysideSplit> wayside_splits;  // none: one wayside unit runs the whole line
  std::vector<TrainSpec> trains;  // after expanding "repeat"
  std::vector<FaultSpec> faults;
  std::optional<GapSpec> gap;
  // low_adhesion: its sections (sorted, disjoint) and the trains on the wheel-rail vehicle
  // (every train when the scenario names none).
  std::vector<AdhesionSectionSpec> low_adhesion;
  std::optional<std::vector<std::uint16_t>> wheel_rail_trains;

  // Whether train `id` runs on the wheel-rail vehicle (the scenario has low-adhesion sections
  // and names the train, or names none).
  [[nodiscard]] bool OnWheelRail(std::uint16_t id) const;
};

// Parses and validates a scenario text (not yet against a line). `file` names it in messages.
Scenario ParseScenario(std::string_view text, const std::string& file);
Scenario LoadScenario(const std::filesystem::path& path);

// The scenario's running line of `line`; InputError "<scenario>: running_line: ..." if the
// line has no such running line or is not the line the scenario names.
const RunningLine& SelectRunningLine(const Scenario& scenario, const Line& line);

// Checks the scenario against its running line: stations of stops exist and lie ahead
// in order, initial fronts on the line, possessions on the line, siding route exists.
void CheckScenarioAgainstLine(const Scenario& scenario, const RunningLine& line);

}  // namespace railproof::sim
