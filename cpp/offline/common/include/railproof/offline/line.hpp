// Line data for the offline scenario simulation: the generated line JSON
// (build/gen/lines/<name>.json, schema "railproof/line-json/1", written by
// `railproof_testgen lines` from spec/lines/*.yaml) loaded into plain structs.
//
// Offline module: allocates, throws InputError with a one-line message naming the file
// and the entry ("<file>: running_lines[0] (up).blocks_mm[3]: ..."). The converter
// validates the YAML already; the loader checks every rule again because the simulation
// and the ground rely on them (REQ-MB-020), so a hand-edited or stale JSON is rejected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace railproof::offline {

// `text` as one line of UTF-8 text: every control character (a newline or a tab in a key, an
// identifier or a file name of the input) is written as an escape ("\n", "\t", "\x01"), and
// every byte that is not UTF-8 as U+FFFD.
std::string OneLine(std::string_view text);

// Any bad input of an offline tool (a data file, an output path): one line "<file>: <entry>:
// <reason>" (or "<file>: <reason>"), which OneLine makes of whatever text it is given.
class InputError : public std::runtime_error {
 public:
  explicit InputError(std::string_view what) : std::runtime_error(OneLine(what)) {}
};

inline constexpr std::string_view kLineSchema = "railproof/line-json/1";

// Half-open section [begin_mm, end_mm) on one running line.
struct Section {
  std::int64_t begin_mm = 0;
  std::int64_t end_mm = 0;
};

struct Gradient {
  Section section;
  std::int64_t permille_x10 = 0;  // + rising in the running direction
};

struct Curve {
  Section section;
  std::int64_t radius_m = 0;
};

struct SpeedLimit {
  Section section;
  std::int64_t kmh = 0;
};

struct Balise {
  std::string id;
  std::int64_t position_mm = 0;
};

struct Station {
  std::string name;
  Section platform;
  std::int64_t stop_mm = 0;
  bool fixed_block = false;
  bool setback = false;
};

struct Points {
  std::string id;
  Section section;  // exactly one virtual block
};

struct Route {
  std::int64_t id = 0;
  Section section;
  std::string points;
  bool reverse = false;
  bool automatic = false;
};

// A level crossing on one running line (spec/design/lc.md §1): centre, road
// width along the track and design warning time (default applied by the converter).
// It occupies [NearMm(), FarMm()) in the running direction, rounded outwards.
struct LevelCrossing {
  std::string id;
  std::int64_t position_mm = 0;      // centre of the road
  std::int64_t width_mm = 0;         // road width along the track, > 0
  std::int64_t warning_time_ms = 0;  // design warning time, >= min_warning_time_ms

  [[nodiscard]] std::int64_t HalfWidthMm() const { return (width_mm + 1) / 2; }
  [[nodiscard]] std::int64_t NearMm() const { return position_mm - HalfWidthMm(); }
  [[nodiscard]] std::int64_t FarMm() const { return position_mm + HalfWidthMm(); }
};

struct RadioCell {
  std::string id;
  Section section;
};

struct Handover {
  std::string id;
  std::int64_t position_mm = 0;
};

// One direction of one track, chainage increasing in the running direction.
struct RunningLine {
  std::string id;
  std::int64_t length_mm = 0;
  std::vector<std::int64_t> blocks_mm;  // boundaries, strictly increasing, 0 .. length
  std::vector<Gradient> gradients;      // cover [0, length) without gap or overlap
  std::vector<Curve> curves;
  std::vector<SpeedLimit> speed_limits;  // cover [0, length)
  std::vector<Balise> balises;           // sorted by position
  std::vector<Station> stations;         // sorted by stop
  std::vector<Points> points;
  std::vector<Route> routes;
  std::vector<LevelCrossing> level_crossings;
  std::vector<RadioCell> radio_cells;  // cover [0, length)
  std::vector<Handover> handovers;     // at cell boundaries
  std::vector<Section> no_stop_sections;
  std::optional<std::int64_t> system_boundary_mm;

  // Gradient (permille x10) and line speed limit (km/h) at a position (clamped to the line).
  [[nodiscard]] std::int64_t GradientAt(std::int64_t pos_mm) const;
  [[nodiscard]] std::int64_t SpeedLimitAt(std::int64_t pos_mm) const;
  // The mean gradient (per mille, + rising) over a train occupying [rear_mm, front_mm]: what
  // a point-mass train of that extent feels (dynamics.hpp). Beyond the line's ends its first
  // and last gradients continue; an extent of zero length gives the gradient at the point.
  [[nodiscard]] double MeanGradientPermille(double rear_mm, double front_mm) const;
  // The mean curve resistance (per mille of the train's weight, CurveResistancePermille) over
  // [rear_mm, front_mm]: each curve's resistance weighted by the part of the train in it;
  // straight track beyond the curves.
  [[nodiscard]] double MeanCurveResistancePermille(double rear_mm, double front_mm) const;
  [[nodiscard]] const Station* FindStation(std::string_view name) const;
  [[nodiscard]] const Points* FindPoints(std::string_view points_id) const;

  // Calls f(i) for every speed limit i acting on a train occupying [rear, front]: a limit on
  // [begin, end) acts from its begin reaching the front until its end leaving the rear
  // (begin <= front, rear < end). Positions in mm, or in the unit of mm_per_unit mm (1000: m).
  template <typename F>
  void ForEachLimitActing(double rear, double front, F&& f, double mm_per_unit = 1.0) const {
    for (std::size_t i = 0; i < speed_limits.size(); ++i) {
      const Section& s = speed_limits[i].section;
      if (static_cast<double>(s.begin_mm) / mm_per_unit <= front && rear < static_cast<double>(s.end_mm) / mm_per_unit) {
        f(i);
      }
    }
  }
};

struct Line {
  std::string file;  // where it was loaded from (for messages)
  std::string name;
  std::string title;
  std::string assumption;
  std::vector<std::string> source;
  std::vector<RunningLine> running_lines;

  // Throws InputError "<file>: unknown running line '<id>' (has: up, down)".
  [[nodiscard]] const RunningLine& Running(std::string_view running_id) const;
};

// Parses and validates a line JSON text; `file` names it in messages. Level crossings are
// rejected (REQ-LC-016) when the extent leaves the line (0, length), the width or warning
// time is not positive, the warning time is below min_warning_time_ms, or two overlap.
// @implements REQ-MB-020 REQ-LC-016
Line ParseLine(std::string_view text, const std::string& file);

// Reads and parses a file (InputError if it cannot be read).
// @implements REQ-MB-020
Line LoadLine(const std::filesystem::path& path);

// <lines_dir>/<name>.json
std::filesystem::path LinePath(const std::filesystem::path& lines_dir, std::string_view name);

}  // namespace railproof::offline
