// The co-simulation's loop, the one both the in-process runner (MobilityRun, dm_run_scene) and the
// vehicle nodelet run; only the ports differ (direct calls there, nodelet exchanges in ROS).
#pragma once

#include "dem_mobility/core/cosim/ports.h"
#include "dem_mobility/core/cosim/vehicle_cosim.h"
#include "dem_mobility/core/mobility/mobility_run.h"

namespace dem_mobility::core {

/// What a run reports as it goes (the vehicle nodelet publishes from it; the runner prints).
class CoSimObserver {
 public:
  virtual ~CoSimObserver() = default;
  /// After the opening exchange and after every step (the command in force is `cmd`).
  virtual void OnStep(const VehicleCoSim& /*sim*/, const DriverCommand& /*cmd*/) {}
  /// Polled every step: true stops the run (interrupted).
  virtual bool StopRequested() { return false; }
};

/// Settle with the brakes on, then the driver every control period, the terrain every coupling
/// interval, history samples at sample_rate, until the duration or a no-go. A SimulationError
/// (non-finite state, a peer that stopped answering) ends it with result.error set and the
/// history so far; configuration errors throw before the first step.
MobilityRunResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver,
                                  CoSimObserver* observer);

}  // namespace dem_mobility::core
