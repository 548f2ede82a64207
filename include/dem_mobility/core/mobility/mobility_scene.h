// A mobility run in one process: the vehicle, the scene's terrain model and its driver called
// directly, through the same loop the nodelets run (cosim/cosim_loop.h).
#pragma once

#include <functional>
#include <memory>

#include "dem_mobility/core/cosim/cosim_loop.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

class MobilityRun {
 public:
  /// Builds the terrain, the driver and the vehicle, and makes the opening exchange (ConfigError
  /// for bad input or a time step above the limit). `stop` (may be empty) is called while the
  /// terrain prepares: once it returns true, Interrupted says where the preparation was.
  explicit MobilityRun(const MobilityRunParams& p, const std::function<bool()>& stop = {});
  /// The same on a terrain built already (e.g. a copy of a prepared soil: one preparation, many runs).
  MobilityRun(const MobilityRunParams& p, std::unique_ptr<TerrainModel> terrain);
  MobilityRunResult Run(CoSimObserver* observer = nullptr);
  VehicleCoSim& sim() { return sim_; }
  Vehicle& vehicle() { return sim_.vehicle(); }
  TerrainPort& terrain_port() { return port_; }
  const TerrainModel& terrain() const { return *terrain_; }
  TerrainModel& mutable_terrain() { return *terrain_; }
  double dt() const { return sim_.dt(); }

 private:
  VehicleSpec spec_;  ///< read once: the terrain, the driver and the vehicle take what they need
  std::unique_ptr<TerrainModel> terrain_;
  LocalTerrainPort port_;
  SceneDriver driver_;
  VehicleCoSim sim_;
};

}  // namespace dem_mobility::core
