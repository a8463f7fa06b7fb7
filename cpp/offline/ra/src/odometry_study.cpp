// Odometry study: margin tables, baseline extension, clearing time and the train-type
// margin check (odometry_study.hpp; D1 §3 items 6, 7, 9; D5 §7.4.2).
#include "railproof/ra/analysis/odometry_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "railproof/generated/ra_params.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::ra::analysis {

namespace rp = params::ra;
using offline::InputError;

// D1's figures in km/h/s (spec/parameters/ra.yaml former_*, km/h/s x 1000) in m/s^2.
VehicleAccelBounds D1VehicleBounds() noexcept {
  constexpr double kKmhSx1000 = 1.0 / 3600.0;  // 0.001 km/h/s in m/s^2
  return VehicleAccelBounds{static_cast<double>(rp::former_accel_min_kmh_s_x1000) * kKmhSx1000,
                            static_cast<double>(rp::former_accel_max_kmh_s_x1000) * kKmhSx1000,
                            static_cast<double>(rp::former_decel_min_kmh_s_x1000) * kKmhSx1000,
                            static_cast<double>(rp::former_decel_max_kmh_s_x1000) * kKmhSx1000};
}

double GravityMS2() noexcept { return static_cast<double>(rp::gravity_mm_s2) / 1000.0; }
double RateErrorFullDegS() noexcept { return static_cast<double>(rp::imu_rate_error_full_udeg_s) / 1e6; }
double RateErrorTenthDegS() noexcept { return static_cast<double>(rp::imu_rate_error_udeg_s) / 1e6; }
double ClearingAccelMS2() noexcept { return static_cast<double>(rp::clearing_accel_mm_s2) / 1000.0; }
double ReferenceMaxCompensationS() noexcept { return static_cast<double>(rp::max_compensation_ms) / 1000.0; }

std::vector<double> StudyTimesS() {
  std::vector<double> t{3, 5, 10, 15, 20, 25};
  t.push_back(static_cast<double>(rp::max_compensation_limit_ms) / 1000.0);  // 32 s
  return t;
}

std::vector<double> StudyGradientsPermille() { return {0, 10, 16, 25, 35}; }

double ImuMarginM(double t_s, double gradient_permille, double rate_error_deg_s) {
  return ra::ErrorBoundM(t_s, gradient_permille, rate_error_deg_s);
}

BaselineExtension BaselineExtensionM(double t_s, double gradient_permille, const VehicleAccelBounds& b) {
  const double gg = GravityMS2() * std::abs(gradient_permille) / 1000.0;
  BaselineExtension e;
  e.slip_front_accel = b.accel_max + gg;
  e.slip_rear_accel = -gg;  // the minimum acceleration including coasting: coasting (D1 §3.4.3)
  e.slide_front_accel = gg;
  e.slide_rear_accel = -(b.decel_max + gg);
  const double half_t2 = 0.5 * t_s * t_s;
  e.slip_m = (e.slip_front_accel - e.slip_rear_accel) * half_t2;
  e.slide_m = (e.slide_front_accel - e.slide_rear_accel) * half_t2;
  e.slide_braked_m = ((-b.decel_min + gg) - e.slide_rear_accel) * half_t2;
  e.worst_m = std::max(e.slip_m, e.slide_m);
  return e;
}

double ClearingTimeS(double distance_m, double accel_m_s2) {
  if (!(accel_m_s2 > 0.0) || distance_m < 0.0) {
    throw InputError("clearing time: distance must be >= 0 and acceleration > 0");
  }
  return std::sqrt(2.0 * distance_m / accel_m_s2);
}

double ClearingCostS(double train_length_m, double margin_per_side_m, double accel_m_s2) {
  return ClearingTimeS(train_length_m + 2.0 * margin_per_side_m, accel_m_s2) -
         ClearingTimeS(train_length_m, accel_m_s2);
}

std::vector<MarginTableRow> MarginTable(const std::vector<double>& times_s,
                                        const std::vector<double>& gradients_permille,
                                        const VehicleAccelBounds& b) {
  std::vector<MarginTableRow> rows;
  for (const double t : times_s) {
    for (const double g : gradients_permille) {
      MarginTableRow r;
      r.t_max_s = t;
      r.gradient_permille = g;
      r.imu_margin_full_m = ImuMarginM(t, g, RateErrorFullDegS());
      r.imu_margin_tenth_m = ImuMarginM(t, g, RateErrorTenthDegS());
      r.baseline = BaselineExtensionM(t, g, b);
      rows.push_back(r);
    }
  }
  return rows;
}

std::int64_t SteepestGradientX10(const offline::Line& line) {
  std::int64_t g = 0;
  for (const auto& rl : line.running_lines) {
    for (const auto& gr : rl.gradients) {
      g = std::max(g, std::abs(gr.permille_x10));
    }
  }
  return g;
}

std::filesystem::path LineOfTrain(const TrainType& t, const std::filesystem::path& lines_dir) {
  const auto us = t.name.rfind('_');
  if (us == std::string::npos || us + 1 >= t.name.size()) {
    throw InputError(t.file + ": name: '" + t.name + "' does not name its line (expected <type>_dN)");
  }
  const std::string prefix = t.name.substr(us + 1) + "_";
  std::vector<std::filesystem::path> found;
  for (const auto& f : offline::ListJsonFiles(lines_dir, "lines")) {
    if (f.filename().string().rfind(prefix, 0) == 0) {
      found.push_back(f);
    }
  }
  if (found.size() != 1) {
    throw InputError(t.file + ": name: train '" + t.name + "' maps to " + std::to_string(found.size()) +
                     " line(s) '" + prefix + "*.json' in " + lines_dir.string() + ", expected exactly one");
  }
  // cross-check: the line's design train has the train's length
  const std::string file = found.front().string();
  const offline::JsonDocument root(offline::ReadInputFile(file, "line file"), file);
  const offline::JsonNode len = root.Key("design_train_length_mm");
  if (len.Int() != t.length_mm) {
    len.Fail("design train length " + std::to_string(len.Int()) + " mm differs from train '" + t.name +
             "' (" + std::to_string(t.length_mm) + " mm): the train does not run on this line");
  }
  return found.front();
}

TrainMarginCheck CheckTrainMargin(const TrainType& t, const offline::Line& line) {
  TrainMarginCheck c;
  c.train = t.name;
  c.train_file = t.file;
  c.line = line.name;
  c.line_file = line.file;
  c.length_m = static_cast<double>(t.length_mm) / 1000.0;
  c.steepest_gradient_permille_x10 = SteepestGradientX10(line);
  c.max_compensation_ms = rp::max_compensation_ms;
  c.rate_error_udeg_s = rp::imu_rate_error_udeg_s;
  c.readhesion_margin_mm = t.readhesion_margin_mm;
  c.error_model_mm = ra::ErrorBoundMm(c.max_compensation_ms,
                                            static_cast<std::int32_t>(c.steepest_gradient_permille_x10),
                                            c.rate_error_udeg_s);
  c.headroom_mm = c.readhesion_margin_mm - c.error_model_mm;
  c.clearing_extra_s =
      ClearingCostS(c.length_m, static_cast<double>(t.readhesion_margin_mm) / 1000.0, ClearingAccelMS2());
  c.meets_target = c.readhesion_margin_mm >= c.error_model_mm;
  return c;
}

}  // namespace railproof::ra::analysis
