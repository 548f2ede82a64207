#include "dem_mobility/core/mobility/ports.h"

#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

void LocalTerrainPort::Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                                std::vector<WheelWrench>* wrenches) {
  model_.Synchronize(step, t, states);
  model_.GetWrenches(wrenches);
  model_.Advance(dt);
}

const TerrainDescription& LocalTerrainPort::description() const { return model_.description(); }

namespace {
DriverParams WithWheelbase(DriverParams p, const VehicleSpec& vehicle) {
  p.wheelbase = vehicle.wheelbase;
  return p;
}
}  // namespace

SceneDriver::SceneDriver(const DriverParams& p, const VehicleSpec& vehicle)
    : powertrain_(vehicle.powertrain),
      driver_(WithWheelbase(p, vehicle), powertrain_, vehicle.TotalMass(), vehicle.wheel_radius(),
              vehicle.driveline_reduction()) {}

DriverCommand SceneDriver::Exchange(const DriverInput& in) {
  DriverCommand c = driver_.Update(in.time, in.period, in.forward_speed, in.drive_shaft_speed);
  c.steering = driver_.Steering(in.lateral_offset, in.heading, in.forward_speed);
  return c;
}

}  // namespace dem_mobility::core
