// The train-motion model of the offline tools (dynamics.hpp).
#include "railproof/offline/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace railproof::offline {

double ResistanceDecel(const Resistance& r, double speed_mps) {
  const double v_kmh = speed_mps * 3.6;
  return kGravity * (r.a0 + r.a1 * v_kmh + r.a2 * v_kmh * v_kmh) / 1000.0;
}

Resistance ConsistResistance(const Consist& c) {
  const double w = c.motor_mass_t + c.trailer_mass_t;
  return Resistance{(1.65 * c.motor_mass_t + 0.78 * c.trailer_mass_t) / w,
                    (0.0247 * c.motor_mass_t + 0.0028 * c.trailer_mass_t) / w,
                    (0.028 + 0.0078 * (c.cars - 1)) / w};
}

double MaxTraction(const TrainPerformance& perf, double speed_mps) {
  if (perf.constant_power_from_mps > 0.0 && speed_mps > perf.constant_power_from_mps) {
    return perf.accel_mps2 * perf.constant_power_from_mps / speed_mps;
  }
  return perf.accel_mps2;
}

double GradeDecel(double gradient_permille, double gravity) { return gravity * gradient_permille / 1000.0; }

double NetAcceleration(const TrainPerformance& perf, const Control& control, double speed_mps,
                       double gradient_permille) {
  double applied = 0.0;
  if (control.emergency) {
    applied = -perf.emergency_decel_mps2;
  } else {
    const double traction = speed_mps < perf.max_speed_mps ? std::clamp(control.traction_mps2, 0.0, MaxTraction(perf, speed_mps)) : 0.0;
    applied = traction - std::clamp(control.brake_mps2, 0.0, perf.service_decel_mps2);
  }
  // At standstill the resistance does not push the train backwards (static friction).
  const double resistance = speed_mps > 0.0 ? ResistanceDecel(perf.resistance, speed_mps) : 0.0;
  return applied - resistance - GradeDecel(gradient_permille);
}

Motion Advance(const Motion& m, double a, double dt_s) {
  Motion out = m;
  if (m.speed <= 0.0 && a <= 0.0) {
    out.speed = 0.0;
    return out;  // standing, brake held
  }
  const double v1 = m.speed + a * dt_s;
  if (v1 < 0.0) {
    // stops within the step: after v / -a, at v^2 / (2 |a|)
    out.position = m.position + m.speed * m.speed / (-2.0 * a);
    out.speed = 0.0;
    return out;
  }
  out.position = m.position + m.speed * dt_s + 0.5 * a * dt_s * dt_s;
  out.speed = v1;
  return out;
}

double SpeedAfter(double speed, double a, double distance) {
  return std::sqrt(std::max(0.0, speed * speed + 2.0 * a * distance));
}

double TimeOver(double distance, double v0, double v1) { return 2.0 * distance / (v0 + v1); }

double TimeToCover(double speed, double a, double distance) {
  if (distance <= 0.0) {
    return 0.0;
  }
  const double disc = speed * speed + 2.0 * a * distance;
  if (disc < 0.0 || (a == 0.0 && speed <= 0.0)) {
    return std::numeric_limits<double>::infinity();  // stops (or stands) before
  }
  if (a == 0.0) {
    return distance / speed;
  }
  // d = v t + a t^2 / 2, the first root; written to stay exact for a small a
  return 2.0 * distance / (speed + std::sqrt(disc));
}

double StoppingDistance(double speed, double decel, double free_running_s) {
  if (speed <= 0.0) {
    return 0.0;
  }
  return speed * std::max(0.0, free_running_s) + speed * speed / (2.0 * decel);
}

double CurveSpeed(double distance, double decel, double free_running_s) {
  if (distance <= 0.0 || decel <= 0.0) {
    return 0.0;
  }
  const double t = std::max(0.0, free_running_s);
  return decel * (std::sqrt(t * t + 2.0 * distance / decel) - t);
}

}  // namespace railproof::offline
