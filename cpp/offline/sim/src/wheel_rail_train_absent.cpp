// The build without Box2D (RAILPROOF_HEAVY_OFFLINE=OFF) has no wheel-rail vehicle
// (wheel_rail_train.hpp): a scenario that needs one is refused.
#include "railproof/sim/wheel_rail_train.hpp"

namespace railproof::sim {

std::unique_ptr<WheelRailTrain> MakeWheelRailTrain(const Scenario& sc, const TrainSpec& train,
                                                   const RunningLine& /*line*/, double /*front_m*/) {
  throw InputError(sc.file + ": " + train.entry +
                   ": runs on the wheel-rail vehicle (low_adhesion), which this build does not have (Box2D, "
                   "RAILPROOF_HEAVY_OFFLINE)");
}

}  // namespace railproof::sim
