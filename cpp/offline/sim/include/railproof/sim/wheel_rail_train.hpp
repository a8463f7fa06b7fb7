// The true motion of a scenario train that runs on the Box2D wheel-rail vehicle
// (ra::analysis::WheelRailVehicle, cpp/offline/ra; spec/design/sim.md) instead of the point
// mass: where the scenario has low-adhesion sections, the achieved traction and braking are
// what the rail allows, and the measured (TG) axle slips under traction and slides under
// braking.
//
// The train is its leading car (the wheel-rail simulator's 35 t motor car, leading bogie
// motored, TG on the trailing axle of that bogie) scaled to the train's performance: full
// notch gives the train's acceleration, brake demand 1 its service deceleration and the
// emergency brake its emergency deceleration on dry rail; its running resistance is the
// train's. The whole train therefore has the adhesion of the rail under that car, and gravity
// acts on the car's pitch (the gradient under its 20 m, joined by vertical curves) rather than
// on the mean gradient under the train; curve resistance is not in it. Wheel-slide protection
// and traction anti-slip act as the simulator's slip control (spec/design/ra.md, ASM-027).
//
// Offline module. The build without Box2D (RAILPROOF_HEAVY_OFFLINE=OFF) has no vehicle:
// MakeWheelRailTrain throws InputError there.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/sim/scenario.hpp"
#include "railproof/sim/sensors.hpp"

namespace railproof::sim {

// The measured axle's adhesion state (creep beyond ra::analysis::TruthSpec's 0.02).
enum class AxleState : std::uint8_t { kRolling, kSlip, kSlide };
inline const char* ToString(AxleState s) {
  switch (s) {
    case AxleState::kRolling: return "rolling";
    case AxleState::kSlip: return "slip";
    case AxleState::kSlide: return "slide";
  }
  return "invalid";
}

struct WheelRailStep {
  offline::Motion end;  // the car body: front (line chainage) and speed (>= 0)
  double accel_mps2 = 0.0;  // mean over the step
  AxleMotion axle;          // the measured axle over the step
  double creep = 0.0;       // the measured axle's at the end
  AxleState state = AxleState::kRolling;
};

class WheelRailTrain {
 public:
  virtual ~WheelRailTrain() = default;
  // Advances by dt_s at time t_s under the brake equipment's applied acceleration (traction
  // minus brake, m/s^2, as the point mass would get it: the traction up to accel_mps2, the
  // brake up to the emergency deceleration).
  virtual WheelRailStep Step(double applied_mps2, double t_s, double dt_s) = 0;
  [[nodiscard]] virtual double CarLengthM() const = 0;
};

// The vehicle of a train standing with its front at `front_m` on `line` with the scenario's
// low-adhesion sections. Throws InputError "<file>: <entry>: ..." when it cannot be built.
std::unique_ptr<WheelRailTrain> MakeWheelRailTrain(const Scenario& sc, const TrainSpec& train,
                                                   const RunningLine& line, double front_m);

}  // namespace railproof::sim
