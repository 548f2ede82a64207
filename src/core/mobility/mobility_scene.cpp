#include "dem_mobility/core/mobility/mobility_scene.h"

#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

MobilityRun::MobilityRun(const MobilityRunParams& p, const std::function<bool()>& stop)
    : spec_(VehicleSpec::Load(p.vehicle_file)),
      terrain_(LoadTerrainModel(p.terrain_file, TerrainVehicleOf(spec_), p.terrain_overrides, stop)),
      port_(*terrain_),
      driver_(p.driver, spec_),
      sim_(p, spec_) {
  terrain_->SetGravity(p.Gravity());  // the soil on the grade too
  sim_.Start(port_);
}

MobilityRun::MobilityRun(const MobilityRunParams& p, std::unique_ptr<TerrainModel> terrain)
    : spec_(VehicleSpec::Load(p.vehicle_file)),
      terrain_(std::move(terrain)),
      port_(*terrain_),
      driver_(p.driver, spec_),
      sim_(p, spec_) {
  terrain_->SetGravity(p.Gravity());  // the soil on the grade too
  sim_.Start(port_);
}

MobilityRunResult MobilityRun::Run(CoSimObserver* observer) {
  return RunCoSimulation(sim_, port_, driver_, observer);
}

}  // namespace dem_mobility::core
