// Train type for the offline braking analysis: the generated train JSON
// (build/gen/trains/<name>.json, schema "railproof/train-json/1", the keys of
// spec/trains/<name>.yaml with integer values) loaded into a plain struct with strict
// validation. Every failure throws offline::InputError "<file>: <entry>: <reason>" (one line).
//
// The design rule of the pattern decelerations (REQ-BR-010) is NOT a load error: the margin
// verification must still compute (negative) margins for a train that violates it and name
// the location; DesignRuleFindings() reports the violation as an additional finding.
//
// Offline module (may allocate and throw).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "railproof/br/patterns.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::offline {

inline constexpr std::string_view kTrainSchema = "railproof/train-json/1";
inline constexpr std::string_view kTrainYamlSchema = "railproof/train/1";

struct Range {
  std::int64_t min = 0;
  std::int64_t max = 0;
};

// spec/trains/<name>.yaml (integers: mm, mm/s, mm/s^2, ms, ppm, km/h).
struct TrainType {
  std::string file;  // where it was loaded from (messages)
  std::string name;
  std::string title;
  std::int64_t length_mm = 0;
  std::int64_t max_speed_kmh = 0;
  std::int64_t accel_max_mm_s2 = 0;
  // braking
  std::int64_t emergency_pattern_mm_s2 = 0;  // beta_e
  std::int64_t service_pattern_mm_s2 = 0;    // beta_n7
  Range emergency_free_running_ms;
  Range service_free_running_ms;
  std::int64_t emergency_overspeed_kmh = 0;
  // supervision (speed-measurement allowance, REQ-BR-007)
  std::int64_t speed_error_ppm = 0;
  std::int64_t speed_error_abs_mm_s = 0;
  // uncertainty set
  Range emergency_deceleration_mm_s2;  // real emergency deceleration
  Range service_deceleration_mm_s2;
  std::int64_t odometry_ppm = 0;
  std::int64_t readhesion_margin_mm = 0;

  // Train's maximum speed in mm/s (km/h * 1000 / 3.6, rounded up).
  [[nodiscard]] std::int64_t MaxSpeedMmS() const;
};

// km/h -> mm/s rounded up (a speed limit or allowance is never understated), exact integers.
std::int64_t SpeedKmhToMmS(std::int64_t kmh);

// Parses and validates a train JSON text; `file` names it in messages. Accepts the schema
// of the generated JSON ("railproof/train-json/1") and, for a direct conversion of the
// YAML, "railproof/train/1". Extra keys of the YAML header (source, assumption) are allowed;
// unknown keys are rejected.
// @implements REQ-BR-010
TrainType ParseTrainType(std::string_view text, const std::string& file);

// Reads and parses a file (InputError if it cannot be read).
// @implements REQ-BR-010
TrainType LoadTrainType(const std::filesystem::path& path);

// Every train type of a directory, or the one file `path` (ListJsonFiles), in name order.
std::vector<TrainType> LoadTrainTypes(const std::filesystem::path& path);

// The pattern values of the runtime (br::TrainData): the maximum of every range,
// overspeed in mm/s rounded up.
br::TrainData ToTrainData(const TrainType& t);

// A running line as the runtime braking module's profile (br::PatternCalculator::SetProfile):
// its gradients, and its speed limits as restrictions (mm/s, km/h rounded up), each capped at
// cap_mm_s (the train's maximum speed; 0: no cap).
std::vector<br::GradientSegment> GradientProfile(const RunningLine& rl);
std::vector<br::RestrictionSegment> PermittedProfile(const RunningLine& rl, std::int64_t cap_mm_s);

// Violations of the design rule of the pattern decelerations (REQ-BR-010): beta_e above the
// lowest real emergency deceleration, beta_n7 above beta_e. Empty when the rule holds.
// Each entry: "<file>: <entry>: <reason>".
// @implements REQ-BR-010
std::vector<std::string> DesignRuleFindings(const TrainType& t);

}  // namespace railproof::offline
