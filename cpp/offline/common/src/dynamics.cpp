#include "railproof/offline/dynamics.hpp"

#include <algorithm>
#include <cmath>

namespace railproof::offline {

double ResistanceDecel(const Resistance& r, double speed_mps) {
  const double v_kmh = speed_mps * 3.6;
  return kGravity * (r.a0 + r.a1 * v_kmh + r.a2 * v_kmh * v_kmh) / 1000.0;
}

double NetAcceleration(const TrainPerformance& perf, const Control& control, double speed_mps,
                       double gradient_permille) {
  double applied = 0.0;
  if (control.emergency) {
    applied = -perf.emergency_decel_mps2;
  } else {
    const double traction = speed_mps < perf.max_speed_mps ? std::clamp(control.traction_mps2, 0.0, perf.accel_mps2) : 0.0;
    applied = traction - std::clamp(control.brake_mps2, 0.0, perf.service_decel_mps2);
  }
  // At standstill the resistance does not push the train backwards (static friction).
  const double resistance = speed_mps > 0.0 ? ResistanceDecel(perf.resistance, speed_mps) : 0.0;
  return applied - resistance - kGravity * gradient_permille / 1000.0;
}

Motion Advance(const Motion& m, double a, double dt_s) {
  Motion out = m;
  if (m.speed_mps <= 0.0 && a <= 0.0) {
    out.speed_mps = 0.0;
    return out;  // standing, brake held
  }
  const double v1 = m.speed_mps + a * dt_s;
  if (v1 < 0.0) {
    // stops within the step: t0 = v / -a, distance v^2 / (2 |a|)
    out.position_m = m.position_m + m.speed_mps * m.speed_mps / (-2.0 * a);
    out.speed_mps = 0.0;
    return out;
  }
  out.position_m = m.position_m + m.speed_mps * dt_s + 0.5 * a * dt_s * dt_s;
  out.speed_mps = v1;
  return out;
}

double CurveSpeed(double distance_m, double decel_mps2, double free_running_s) {
  if (distance_m <= 0.0 || decel_mps2 <= 0.0) {
    return 0.0;
  }
  const double t = std::max(0.0, free_running_s);
  return decel_mps2 * (std::sqrt(t * t + 2.0 * distance_m / decel_mps2) - t);
}

double StoppingDistance(double speed_mps, double decel_mps2, double free_running_s) {
  if (speed_mps <= 0.0) {
    return 0.0;
  }
  return speed_mps * std::max(0.0, free_running_s) + speed_mps * speed_mps / (2.0 * decel_mps2);
}

}  // namespace railproof::offline
