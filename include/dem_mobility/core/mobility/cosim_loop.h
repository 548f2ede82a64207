// The co-simulation's loop, the one both the in-process runner (MobilityRun, dm_run_scene) and the
// vehicle nodelet run; only the ports differ (direct calls there, nodelet exchanges in ROS).
#pragma once

#include <chrono>

#include "dem_mobility/core/mobility/ports.h"
#include "dem_mobility/core/mobility/vehicle_cosim.h"
#include "dem_mobility/core/mobility/mobility_result.h"

namespace dem_mobility::core {

/// The loop's own state between two steps: what a checkpoint keeps beside the vehicle, the
/// terrain and the driver (common/state_archive.h, mobility/mobility_run.h).
struct CoSimLoopState {
  MobilityRunResult r;   ///< the history, ledger and counts so far
  DriverCommand cmd;     ///< the command in force
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();  ///< the chassis frame at the driver's start
  // (not kept: the wall clock of this process's part of the run)
  double wall_before = 0.0;  ///< wall seconds of the run before this process took it up
  std::chrono::steady_clock::time_point wall0 = std::chrono::steady_clock::now();
  /// Wall seconds of the run so far, over every process that ran a part of it.
  double WallTime() const {
    return wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  }
  template <class Ar>
  void Io(Ar& ar) {
    ar.Tag("loop");
    r.Io(ar);
    ar(cmd, p0);
  }
};

/// What a run reports as it goes (the vehicle nodelet publishes from it; the runner prints).
class CoSimObserver {
 public:
  virtual ~CoSimObserver() = default;
  /// After the opening exchange and after every step (the command in force is `cmd`).
  virtual void OnStep(const VehicleCoSim& /*sim*/, const DriverCommand& /*cmd*/) {}
  /// Before every step, before StopRequested: the loop's state there, where a run taken up again
  /// from it goes on bit for bit (the in-process runner writes its checkpoints here).
  virtual void AtStepStart(const VehicleCoSim& /*sim*/, const CoSimLoopState& /*state*/) {}
  /// Polled before every step: true stops the run (interrupted).
  virtual bool StopRequested() { return false; }
};

/// Settle with the brakes on, then the driver every control period, the terrain every coupling
/// interval, history samples at sample_rate, until the duration or a no-go. A SimulationError
/// (non-finite state, a peer that stopped answering) ends it with result.error set and the
/// history so far; configuration errors throw before the first step.
/// `resume`: the loop state of a checkpoint, with the vehicle, terrain and driver read back from
/// it (then the run goes on where it was; nullptr: from the start).
MobilityRunResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver,
                                  CoSimObserver* observer, const CoSimLoopState* resume = nullptr);

}  // namespace dem_mobility::core
