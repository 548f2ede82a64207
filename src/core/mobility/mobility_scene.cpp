#include "dem_mobility/core/mobility/mobility_scene.h"

#include "dem_mobility/core/vehicle/vehicle.h"

namespace dem_mobility {

MobilityRun::MobilityRun(const MobilityRunParams& p)
    : terrain_(LoadTerrainModel(p.terrain_file, TerrainVehicle{LoadTireGeometry(p.vehicle_file), kWheels})),
      port_(*terrain_),
      driver_(p.driver, p.vehicle_file),
      sim_(p) {
  sim_.Start(port_);
}

MobilityRunResult MobilityRun::Run(CoSimObserver* observer) {
  return RunCoSimulation(sim_, port_, driver_, observer);
}

}  // namespace dem_mobility
