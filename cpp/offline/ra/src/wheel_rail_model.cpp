// Wheel-rail simulator: adhesion law (ASM-027), line geometry of a scenario, odometry
// sections and configuration (spec/design/ra.md §6).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

namespace rp = params::ra;

double CurtiusKnifflerMu(double v_kmh) { return 7.5 / (std::fabs(v_kmh) + 44.0) + 0.161; }

double CreepCurve(double creep, const AdhesionLaw& law) {
  const double a = std::fabs(creep);
  double y = 0.0;
  if (a <= law.peak_creep) {
    y = a / law.peak_creep;
  } else if (a <= law.tail_creep) {
    y = 1.0 - (1.0 - law.tail_ratio) * (a - law.peak_creep) / (law.tail_creep - law.peak_creep);
  } else {
    y = law.tail_ratio;
  }
  return creep < 0.0 ? -y : y;
}

double CreepOf(double wheel_speed_mps, double v_mps, const AdhesionLaw& law) {
  return (wheel_speed_mps - v_mps) / std::max(std::fabs(v_mps), law.creep_floor_mps);
}

double AdhesionCoefficient(double creep, double v_mps, double rail_factor, const AdhesionLaw& law) {
  return CurtiusKnifflerMu(v_mps * 3.6) * rail_factor * CreepCurve(creep, law);
}

const char* ToString(SlipKind k) { return k == SlipKind::kSlip ? "slip" : "slide"; }

const char* ToString(ScenarioStart s) {
  switch (s) {
    case ScenarioStart::kAtRest: return "at_rest";
    case ScenarioStart::kLeadIn: return "lead_in";
    case ScenarioStart::kInMotion: return "in_motion";
  }
  return "unknown";
}

// Ramp from rest at accel to the speed, then held for hold_s.
double LeadInDistanceM(const LeadInSpec& lead, double speed_mps) {
  return speed_mps * speed_mps / (2.0 * lead.accel_mps2) + speed_mps * lead.hold_s;
}

const char* ToString(SensorFaultKind k) {
  switch (k) {
    case SensorFaultKind::kTgDropout: return "tg_dropout";
    case SensorFaultKind::kTgStuck: return "tg_stuck";
    case SensorFaultKind::kTgBurst: return "tg_burst";
    case SensorFaultKind::kTgEdgeInvalid: return "tg_edge_invalid";
    case SensorFaultKind::kImuNan: return "imu_nan";
    case SensorFaultKind::kImuGap: return "imu_gap";
    case SensorFaultKind::kImuTimestamps: return "imu_timestamps";
    case SensorFaultKind::kImuOutOfRange: return "imu_out_of_range";
    case SensorFaultKind::kCycleTime: return "cycle_time";
  }
  return "invalid";
}

// ---- geometry ---------------------------------------------------------------------------------
namespace {
// Half length of the vertical curve at change point i (i >= 1).
double HalfCurve(const VerticalAlignment& v, std::size_t i) {
  return v.vertical_curve_radius_m * std::fabs(v.gradients[i].permille - v.gradients[i - 1].permille) / 2000.0;
}

// Linear ramp of a curve's value at s: 0 outside, full inside, linear over the transitions.
double CurveRamp(const HorizontalCurve& c, double s) {
  if (s < c.begin_m || s >= c.end_m) {
    return 0.0;
  }
  if (c.transition_m <= 0.0) {
    return 1.0;
  }
  if (s < c.begin_m + c.transition_m) {
    return (s - c.begin_m) / c.transition_m;
  }
  if (s > c.end_m - c.transition_m) {
    return (c.end_m - s) / c.transition_m;
  }
  return 1.0;
}
}  // namespace

double GradientPermilleAt(const VerticalAlignment& v, double s_m) {
  if (v.gradients.empty()) {
    return 0.0;
  }
  // The segment whose constant part or adjacent half curves contain s.
  std::size_t i = 0;
  while (i + 1 < v.gradients.size() && v.gradients[i + 1].from_m <= s_m) {
    ++i;
  }
  // Curve at change point i (entering segment i) or i + 1 (leaving it).
  if (i >= 1) {
    const double h = HalfCurve(v, i);
    const double c = v.gradients[i].from_m;
    if (h > 0.0 && s_m < c + h) {
      const double g0 = v.gradients[i - 1].permille;
      const double g1 = v.gradients[i].permille;
      return g0 + (g1 - g0) * (s_m - (c - h)) / (2.0 * h);
    }
  }
  if (i + 1 < v.gradients.size()) {
    const double h = HalfCurve(v, i + 1);
    const double c = v.gradients[i + 1].from_m;
    if (h > 0.0 && s_m > c - h) {
      const double g0 = v.gradients[i].permille;
      const double g1 = v.gradients[i + 1].permille;
      return g0 + (g1 - g0) * (s_m - (c - h)) / (2.0 * h);
    }
  }
  return v.gradients[i].permille;
}

double CurvatureAt(const std::vector<HorizontalCurve>& curves, double s_m) {
  double k = 0.0;
  for (const auto& c : curves) {
    k += CurveRamp(c, s_m) / c.radius_m;
  }
  return k;
}

double CantMmAt(const std::vector<HorizontalCurve>& curves, double s_m) {
  double m = 0.0;
  for (const auto& c : curves) {
    m += CurveRamp(c, s_m) * c.cant_mm;
  }
  return m;
}

// ---- odometry sections and configuration ------------------------------------------------------
std::vector<ra::OdometrySection> OdometrySectionsOf(const WheelRailScenario& sc) {
  const auto& v = sc.vertical;
  const std::int64_t tmax = sc.odometry.max_compensation_ms.value_or(rp::max_compensation_ms);
  // Breakpoints of the piecewise-linear gradient: the extreme values lie on them.
  std::vector<double> cuts;
  cuts.push_back(v.begin_m);
  for (std::size_t i = 1; i < v.gradients.size(); ++i) {
    cuts.push_back(v.gradients[i].from_m);
  }
  cuts.push_back(v.end_m);
  std::vector<ra::OdometrySection> out;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i];
    const double b = cuts[i + 1];
    // g(s) is piecewise linear with breakpoints at the vertical curves' ends.
    double g = std::max(std::fabs(GradientPermilleAt(v, a)), std::fabs(GradientPermilleAt(v, b)));
    for (std::size_t j = 1; j < v.gradients.size(); ++j) {
      for (const double p : {v.gradients[j].from_m - HalfCurve(v, j), v.gradients[j].from_m + HalfCurve(v, j)}) {
        if (p > a && p < b) {
          g = std::max(g, std::fabs(GradientPermilleAt(v, p)));
        }
      }
    }
    ra::OdometrySection s;
    s.begin_mm = std::llround(a * 1000.0);
    s.end_mm = std::llround(b * 1000.0);
    s.gradient_permille_x10 = static_cast<std::int32_t>(std::ceil(g * 10.0 - 1e-9));
    s.max_compensation_ms = tmax;
    s.margin_mm = 0;
    if (!out.empty() && s.end_mm - s.begin_mm < 1000) {
      out.back().end_mm = s.end_mm;  // merge a sliver into the previous section
      out.back().gradient_permille_x10 = std::max(out.back().gradient_permille_x10, s.gradient_permille_x10);
      continue;
    }
    out.push_back(s);
  }
  if (out.size() > static_cast<std::size_t>(ra::kMaxSections)) {
    throw offline::InputError(sc.file + ": vertical.gradients: " + std::to_string(out.size()) +
                     " odometry sections, more than the odometry's capacity " +
                     std::to_string(ra::kMaxSections));
  }
  return out;
}

ra::OdometryConfig OdometryConfigOf(const WheelRailScenario& sc,
                                          const std::vector<ra::OdometrySection>& sections) {
  ra::OdometryConfig c;
  c.method = ra::Method::kImu;
  c.wheel_diameter_um =
      std::llround(sc.vehicle.wheel_diameter_m * (1.0 + sc.tg.calibration_error_ppm * 1e-6) * 1e6);
  c.train_length_mm = std::llround(sc.vehicle.length_m * 1000.0);
  // Ta never below its floor on the sections (design note §4, ASM-028)
  c.detect_threshold_mm_s2 =
      std::max(sc.odometry.detect_threshold_mm_s2.value_or(rp::detect_threshold_mm_s2),
               ra::DetectThresholdFloorMmS2(sections.data(), static_cast<int>(sections.size())));
  c.start_points = static_cast<std::uint8_t>(sc.odometry.start_points.value_or(static_cast<int>(rp::parallel_start_points)));
  c.imu_rate_error_udeg_s = sc.odometry.rate_error_udeg_s.value_or(rp::imu_rate_error_udeg_s);
  c.sections = sections.data();
  c.section_count = static_cast<int>(sections.size());
  c.initial_front_mm = std::llround(sc.initial_front_m * 1000.0);
  return c;
}

}  // namespace railproof::ra::analysis
