// libFuzzer target: the wheel-rail scenario loader of wheelrail_sim and odometry_study
// (ra::analysis::ParseWheelRailScenario, cpp/offline/ra/src/wheel_rail_scenario.cpp) and what
// the study derives from a scenario before it simulates (the odometry sections and
// configuration, the alignment's gradient, curvature and cant; wheel_rail_model.cpp), on any
// bytes, structure-aware (json_fuzz.hpp). Seeds: the committed corpus and spec/wheelrail.
// Oracle: every rejection is the project's input error in the one form "<file>: <entry>:
// <reason>", no crash and no undefined behaviour (ASan+UBSan), and an accepted scenario is one
// the simulation has a track for: curves, adhesion zones, balises and the train on the
// vertical alignment, gradients sorted from its begin, fault windows ordered and bounded, a
// step dividing the 10 ms IMU period, and finite geometry everywhere on the alignment.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "json_fuzz.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace {

namespace an = railproof::ra::analysis;
using railproof::fuzz::Require;

const std::string kFile = "wheelrail.json";

bool Within(double b, double e, const an::VerticalAlignment& v) { return v.begin_m <= b && b < e && e <= v.end_m; }

void CheckAccepted(const an::WheelRailScenario& sc) {
  const an::VerticalAlignment& v = sc.vertical;
  Require(sc.duration_s > 0.0 && sc.duration_s <= 3600.0, "duration within (0, 3600] s");
  Require(sc.step_us > 0 && 10'000 % sc.step_us == 0, "step dividing the IMU period");
  Require(std::isfinite(v.begin_m) && std::isfinite(v.end_m) && v.end_m - v.begin_m >= 100.0 &&
              !v.gradients.empty() && v.gradients.front().from_m == v.begin_m,
          "alignment of at least 100 m, gradients from its begin");
  for (std::size_t i = 1; i < v.gradients.size(); ++i) {
    Require(v.gradients[i - 1].from_m < v.gradients[i].from_m && v.gradients[i].from_m < v.end_m, "gradients sorted");
  }
  for (const an::HorizontalCurve& c : sc.curves) {
    Require(Within(c.begin_m, c.end_m, v), "curves on the alignment");
  }
  for (const an::AdhesionZone& z : sc.rail.zones) {
    Require(Within(z.begin_m, z.end_m, v), "adhesion zones on the alignment");
  }
  for (const an::BalisePoint& b : sc.balises) {
    Require(v.begin_m <= b.position_m && b.position_m < v.end_m, "balises on the alignment");
  }
  Require(sc.initial_front_m - sc.vehicle.length_m >= v.begin_m && sc.initial_front_m < v.end_m, "the train on the alignment");
  for (const an::SensorFault& f : sc.faults) {
    Require(0.0 <= f.from_s && f.from_s < f.to_s && f.to_s <= 1e6 && f.from_s < sc.duration_s && std::isfinite(f.value),
            "fault windows ordered, bounded and beginning in the run");
  }
  // what the study derives before it simulates
  const std::vector<railproof::ra::OdometrySection> sections = an::OdometrySectionsOf(sc);
  const railproof::ra::OdometryConfig config = an::OdometryConfigOf(sc, sections);
  Require(config.section_count == static_cast<int>(sections.size()), "one configuration section per section");
  for (int k = 0; k <= 8; ++k) {
    const double s = v.begin_m + (v.end_m - v.begin_m) * k / 8.0;
    Require(std::isfinite(an::GradientPermilleAt(v, s)) && std::isfinite(an::CurvatureAt(sc.curves, s)) &&
                std::isfinite(an::CantMmAt(sc.curves, s)),
            "finite geometry on the alignment");
  }
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { CheckAccepted(an::ParseWheelRailScenario(text, kFile)); });
}
