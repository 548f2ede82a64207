// The vehicle side of the lock-step co-simulation: the 33-body vehicle on a grade (gravity
// rotated; x uphill), stepping in lock-step with a terrain.
#pragma once

#include <memory>
#include <vector>

#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/mobility/ports.h"
#include "dem_mobility/core/mobility/mobility_params.h"
#include "dem_mobility/core/vehicle/vehicle.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

class StateReader;
class StateWriter;

class VehicleCoSim {
 public:
  /// The vehicle of `spec` (read from p.vehicle_file) with its tires just touching the plane z = 0.
  VehicleCoSim(const MobilityRunParams& p, const VehicleSpec& spec);
  /// The opening exchange (step 0), then the time step: time_step, or time_step_safety x the
  /// smallest critical step of the vehicle's elements and the terrain contact it reported. A
  /// terrain with a step of its own h (a DEM soil) is exchanged with every coupling_interval x h:
  /// an automatic step is then h / m, the largest such step within the limit; a given one must
  /// make dt x coupling_interval a whole multiple of h.
  /// Throws ConfigError (naming the scene file and time_step) for a step above that limit.
  void Start(TerrainPort& terrain);
  /// Instead of Start: the vehicle and the exchange as a checkpoint has them (common/
  /// state_archive.h), the time step and coupling as the run written chose them.
  void Restore(StateReader& in);
  void Save(StateWriter& out) const;
  /// One step; exchanges with the terrain when the step index is a multiple of the interval.
  void Step(TerrainPort& terrain);

  Vehicle& vehicle() { return *vehicle_; }
  const Vehicle& vehicle() const { return *vehicle_; }
  const MobilityRunParams& params() const { return p_; }
  long step() const { return vehicle_->system().step_count(); }
  double time() const { return vehicle_->system().time(); }     ///< since the start of settling
  double driver_time() const { return time() - p_.settle_time; } ///< since the driver's start
  double dt() const { return dt_; }
  /// Vehicle steps per exchange in use: the scene's, or with a terrain of its own step (a DEM
  /// soil) and an automatic step, the vehicle steps that fit in one terrain step times the scene's.
  int coupling_interval() const { return coupling_; }
  const TimeStepLimit& limit() const { return limit_; }
  long settle_steps() const { return settle_steps_; }
  long exchanges() const { return exchanges_; }
  long last_exchange_step() const { return last_exchange_; }
  const std::vector<WheelState>& wheel_states() const { return states_; }
  const std::vector<WheelWrench>& wheel_wrenches() const { return wrenches_; }

 private:
  template <class Ar>
  void Io(Ar& ar);
  void Exchange(TerrainPort& terrain);
  void CheckContactLimit();
  MobilityRunParams p_;
  std::unique_ptr<Vehicle> vehicle_;
  double dt_ = 0.0;
  int coupling_ = 1;
  TimeStepLimit limit_;
  long settle_steps_ = 0, exchanges_ = 0, last_exchange_ = -1;
  double checked_stiffness_ = -1.0, checked_damping_ = -1.0;
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
};

}  // namespace dem_mobility::core
