// Train type loader for the offline braking analysis (train_type.hpp).
#include "railproof/offline/train_type.hpp"

#include <algorithm>
#include <string>

#include "railproof/offline/json_reader.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::offline {

using offline::InputError;
using offline::JsonNode;

std::int64_t SpeedKmhToMmS(std::int64_t kmh) { return (kmh * 10000 + 35) / 36; }

std::int64_t TrainType::MaxSpeedMmS() const { return SpeedKmhToMmS(max_speed_kmh); }

namespace {

// Acceleration and deceleration of a train type (spec/schemas/train.schema.json).
constexpr std::int64_t kMaxTrainAccelMmS2 = 5000;
static_assert(kMaxTrainAccelMmS2 <= br::kMaxAccelerationMmS2);

Range RangeIn(const JsonNode& n, std::int64_t lo, std::int64_t hi, const char* unit) {
  const auto [min, max] = n.IntPairIn(lo, hi, unit);
  return Range{min, max};
}

}  // namespace

// @implements REQ-BR-010
TrainType ParseTrainType(std::string_view text, const std::string& file) {
  const JsonDocument root(text, file);
  root.AllowOnly({"schema", "name", "title", "source", "assumption", "length_mm", "max_speed_kmh", "accel_max_mm_s2",
                  "braking", "supervision", "uncertainty", "design_rule_violations"});
  const std::string schema = root.Key("schema").String();
  if (schema != kTrainSchema && schema != kTrainYamlSchema) {
    root.Key("schema").Fail("unsupported schema '" + schema + "' (expected '" + std::string(kTrainSchema) + "')");
  }
  TrainType t;
  t.file = file;
  t.name = root.Key("name").String();
  if (t.name.empty()) {
    root.Key("name").Fail("empty name");
  }
  if (const auto title = root.OptKey("title")) {
    t.title = title->String();
  }
  if (const auto src = root.OptKey("source")) {
    for (const auto& s : src->Array()) {
      (void)s.String();
    }
  }
  if (const auto a = root.OptKey("assumption")) {
    (void)a->String();
  }
  // the converter's note of REQ-BR-010 violations (informational; DesignRuleFindings
  // recomputes them from the values)
  if (const auto v = root.OptKey("design_rule_violations")) {
    for (const auto& s : v->Array()) {
      (void)s.String();
    }
  }
  // The ranges of spec/schemas/train.schema.json (the domain the braking models are built and
  // tested for), each within the runtime's input range (br::kMax*): they bound the design
  // tools' loops (the speed-check allowance is checked at every mm/s up to the maximum speed
  // plus the overspeed) and keep the margin arithmetic in range.
  t.length_mm = root.Key("length_mm").IntIn(1000, 1'000'000, "mm");
  t.max_speed_kmh = root.Key("max_speed_kmh").IntIn(1, 300, "km/h");
  t.accel_max_mm_s2 = root.Key("accel_max_mm_s2").IntIn(1, kMaxTrainAccelMmS2, "mm/s^2");

  const JsonNode br = root.Key("braking");
  br.AllowOnly({"emergency_pattern_mm_s2", "service_pattern_mm_s2", "emergency_free_running_ms",
                "service_free_running_ms", "emergency_overspeed_kmh"});
  t.emergency_pattern_mm_s2 = br.Key("emergency_pattern_mm_s2").IntIn(1, kMaxTrainAccelMmS2, "mm/s^2");
  t.service_pattern_mm_s2 = br.Key("service_pattern_mm_s2").IntIn(1, kMaxTrainAccelMmS2, "mm/s^2");
  t.emergency_free_running_ms = RangeIn(br.Key("emergency_free_running_ms"), 0, br::kMaxTimeMs, "ms");
  t.service_free_running_ms = RangeIn(br.Key("service_free_running_ms"), 0, br::kMaxTimeMs, "ms");
  t.emergency_overspeed_kmh = br.Key("emergency_overspeed_kmh").IntIn(0, 30, "km/h");

  const JsonNode sv = root.Key("supervision");
  sv.AllowOnly({"speed_error_ppm", "speed_error_abs_mm_s"});
  t.speed_error_ppm = sv.Key("speed_error_ppm").IntIn(0, 100'000, "ppm");
  t.speed_error_abs_mm_s = sv.Key("speed_error_abs_mm_s").IntIn(0, 10'000, "mm/s");

  const JsonNode un = root.Key("uncertainty");
  un.AllowOnly({"emergency_deceleration_mm_s2", "service_deceleration_mm_s2", "odometry_ppm", "readhesion_margin_mm"});
  t.emergency_deceleration_mm_s2 = RangeIn(un.Key("emergency_deceleration_mm_s2"), 1, kMaxTrainAccelMmS2, "mm/s^2");
  t.service_deceleration_mm_s2 = RangeIn(un.Key("service_deceleration_mm_s2"), 1, kMaxTrainAccelMmS2, "mm/s^2");
  t.odometry_ppm = un.Key("odometry_ppm").IntIn(0, 100'000, "ppm");
  t.readhesion_margin_mm = un.Key("readhesion_margin_mm").IntIn(0, 1'000'000, "mm");
  return t;
}

// @implements REQ-BR-010
TrainType LoadTrainType(const std::filesystem::path& path) {
  return ParseTrainType(ReadInputFile(path, "train type"), path.string());
}

std::vector<TrainType> LoadTrainTypes(const std::filesystem::path& path) {
  std::vector<TrainType> types;
  for (const auto& f : ListJsonFiles(path, "train types")) {
    types.push_back(LoadTrainType(f));
  }
  return types;
}

br::TrainData ToTrainData(const TrainType& t) {
  br::TrainData d;
  d.length_mm = t.length_mm;
  d.accel_max_mm_s2 = t.accel_max_mm_s2;
  d.beta_e_mm_s2 = t.emergency_pattern_mm_s2;
  d.beta_n7_mm_s2 = t.service_pattern_mm_s2;
  d.emergency_free_running_ms = t.emergency_free_running_ms.max;
  d.service_free_running_ms = t.service_free_running_ms.max;
  d.overspeed_mm_s = SpeedKmhToMmS(t.emergency_overspeed_kmh);
  d.speed_error_ppm = t.speed_error_ppm;
  d.speed_error_abs_mm_s = t.speed_error_abs_mm_s;
  return d;
}

// @implements REQ-BR-010
std::vector<std::string> DesignRuleFindings(const TrainType& t) {
  std::vector<std::string> out;
  if (t.emergency_pattern_mm_s2 > t.emergency_deceleration_mm_s2.min) {
    out.push_back(t.file + ": braking.emergency_pattern_mm_s2: beta_e " + std::to_string(t.emergency_pattern_mm_s2) +
                  " mm/s^2 exceeds the lowest real emergency deceleration " +
                  std::to_string(t.emergency_deceleration_mm_s2.min) +
                  " mm/s^2 (uncertainty.emergency_deceleration_mm_s2) (REQ-BR-010)");
  }
  if (t.service_pattern_mm_s2 > t.emergency_pattern_mm_s2) {
    out.push_back(t.file + ": braking.service_pattern_mm_s2: beta_n7 " + std::to_string(t.service_pattern_mm_s2) +
                  " mm/s^2 exceeds beta_e " + std::to_string(t.emergency_pattern_mm_s2) + " mm/s^2 (REQ-BR-010)");
  }
  return out;
}

std::vector<br::GradientSegment> GradientProfile(const RunningLine& rl) {
  std::vector<br::GradientSegment> out;
  for (const auto& g : rl.gradients) {
    out.push_back({g.section.begin_mm, g.section.end_mm, g.permille_x10});
  }
  return out;
}

std::vector<br::RestrictionSegment> PermittedProfile(const RunningLine& rl, std::int64_t cap_mm_s) {
  std::vector<br::RestrictionSegment> out;
  for (const auto& s : rl.speed_limits) {
    std::int64_t v = SpeedKmhToMmS(s.kmh);
    if (cap_mm_s > 0) {
      v = std::min(v, cap_mm_s);
    }
    out.push_back({s.section.begin_mm, s.section.end_mm, v});
  }
  return out;
}

}  // namespace railproof::offline
