#include "dem_mobility/core/cosim/ports.h"

#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle.h"

namespace dem_mobility {

void LocalTerrainPort::Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                                std::vector<WheelWrench>* wrenches) {
  model_.Synchronize(step, t, states);
  model_.GetWrenches(wrenches);
  model_.Advance(dt);
}

const TerrainDescription& LocalTerrainPort::description() const { return model_.description(); }

SceneDriver::SceneDriver(const DriverParams& p, const std::string& vehicle_file)
    : vehicle_(Vehicle::Load(vehicle_file, Eigen::Vector3d::Zero())),
      driver_(p, vehicle_->powertrain(), vehicle_->system().TotalMass(), vehicle_->tire().radius,
              vehicle_->driveline_reduction()) {}

SceneDriver::~SceneDriver() = default;

DriveCommand SceneDriver::Exchange(const DriveInput& in) {
  return driver_.Update(in.time, in.period, in.forward_speed, in.drive_shaft_speed);
}

}  // namespace dem_mobility
