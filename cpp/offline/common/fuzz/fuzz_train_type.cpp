// libFuzzer target: the train-type loader (offline::ParseTrainType, cpp/offline/common/src/
// train_type.cpp) on any bytes, structure-aware (json_fuzz.hpp). Seeds: the committed corpus
// and the generated train types (build/gen/trains). Oracle: every rejection is the project's
// input error in the one form "<file>: <entry>: <reason>", no crash and no undefined behaviour
// (ASan+UBSan), and an accepted train type lies within the ranges of
// spec/schemas/train.schema.json (the maximum speed bounds the design tools' loops), its
// ranges are [min, max] with min <= max, and its design-rule findings (REQ-BR-010) are
// messages of the same form.
#include <cstddef>
#include <cstdint>
#include <string>

#include "json_fuzz.hpp"
#include "railproof/offline/train_type.hpp"

namespace {

namespace off = railproof::offline;
using railproof::fuzz::Require;

const std::string kFile = "train.json";

bool In(std::int64_t v, std::int64_t lo, std::int64_t hi) { return lo <= v && v <= hi; }
bool In(const off::Range& r, std::int64_t lo, std::int64_t hi) { return In(r.min, lo, hi) && In(r.max, lo, hi) && r.min <= r.max; }

void CheckAccepted(const off::TrainType& t) {
  Require(In(t.max_speed_kmh, 1, 300) && In(t.emergency_overspeed_kmh, 0, 30), "speeds within the schema's ranges");
  Require(In(t.length_mm, 1000, 1'000'000) && In(t.accel_max_mm_s2, 1, 5000) && In(t.emergency_pattern_mm_s2, 1, 5000) &&
              In(t.service_pattern_mm_s2, 1, 5000),
          "length and accelerations within the schema's ranges");
  Require(In(t.emergency_free_running_ms, 0, 60'000) && In(t.service_free_running_ms, 0, 60'000) &&
              In(t.emergency_deceleration_mm_s2, 1, 5000) && In(t.service_deceleration_mm_s2, 1, 5000),
          "ranges [min, max] within the schema's");
  Require(In(t.speed_error_ppm, 0, 100'000) && In(t.speed_error_abs_mm_s, 0, 10'000) && In(t.odometry_ppm, 0, 100'000) &&
              In(t.readhesion_margin_mm, 0, 1'000'000),
          "allowances within the schema's ranges");
  Require(t.MaxSpeedMmS() > 0 && t.MaxSpeedMmS() <= 83'334, "maximum speed in mm/s");
  (void)off::ToTrainData(t);
  for (const std::string& finding : off::DesignRuleFindings(t)) {
    railproof::fuzz::CheckMessage(kFile, finding);
  }
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

// @verifies REQ-BR-010
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { CheckAccepted(off::ParseTrainType(text, kFile)); });
}
