// The paper's vehicle-on-road scene (CI = 300 case) as a lock-step co-simulation: the vehicle side
// (VehicleCoSim), a terrain behind a TerrainPort and a driver behind a DriverPort. The loop that
// runs them (RunCoSimulation) is the one both the in-process runner (RoadScene, dm_run_scene) and
// the vehicle nodelet use; only the ports differ (direct calls here, nodelet channels in ROS).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/cosim/exchange.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/driver.h"
#include "dem_mobility/core/vehicle/vehicle.h"

namespace dem_mobility {

class YamlReader;

/// Settings of the speed-made-good detector.
struct PlateauParams {
  double window = 5.0;        ///< [s] trailing window the steady state is judged on
  double tolerance = 0.05;    ///< [m/s^2] largest |dv/dt| in the window that counts as steady
  double stall_speed = 0.2;   ///< [m/s] below this after stall_time: no-go
  double stall_time = 5.0;    ///< [s]
};

struct RoadSceneParams {
  std::string file;           ///< the scene file (for messages)
  std::string vehicle_file, terrain_file;
  double grade_deg = 0.0;
  double duration = 40.0;
  double settle_time = 0.5;   ///< [s] brakes on, driver off, before the driver's t = 0
  double time_step = 0.0;     ///< 0: auto = time_step_safety x critical step
  double time_step_safety = 0.5;
  int coupling_interval = 1;  ///< vehicle steps per terrain exchange (wrenches held in between)
  DriverParams driver;
  PlateauParams plateau;
  double sample_rate = 100.0; ///< [Hz] history samples
  static RoadSceneParams Read(const YamlReader& y);
};

/// One history sample (t from the driver's start).
struct RoadSample {
  double t, x, speed, speed_command, drive_shaft_speed, drive_torque, brake_effort;
  bool wot_limited;
};

struct SpeedMadeGood {
  double value = 0.0;       ///< [m/s]
  std::string status;       ///< steady | command_limited | no_go | not_steady
  double window_slope = 0.0;///< dv/dt over the judging window [m/s^2]
  double window_std = 0.0;  ///< speed standard deviation in the window [m/s]
};

/// Judges the speed history: a plateau under full throttle, the command reached, or a stall.
SpeedMadeGood DetectSpeedMadeGood(const std::vector<RoadSample>& h, const PlateauParams& p, double v_max);

struct RoadResult {
  SpeedMadeGood smg;
  std::vector<RoadSample> history;
  double dt = 0.0, dt_crit = 0.0;
  std::string dt_limit_element;
  long steps = 0, exchanges = 0, driver_updates = 0;
  double sim_time = 0.0, wall_time = 0.0;  ///< sim_time: from the driver's start
  bool ended_early = false;
  bool interrupted = false; ///< stopped from outside (shutdown) before the end
  std::string error;        ///< empty on success
};

/// The terrain as the vehicle sees it: wheel states of step `step` in, wrenches for that step out.
/// `dt` is the vehicle's step (0 at the opening exchange, before the step is chosen).
class TerrainPort {
 public:
  virtual ~TerrainPort() = default;
  virtual void Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                        std::vector<WheelWrench>* wrenches) = 0;
};

/// The driver as the vehicle sees it.
class DriverPort {
 public:
  virtual ~DriverPort() = default;
  virtual DriveCommand Exchange(const DriveInput& in) = 0;
};

/// The vehicle side: the 33-body vehicle on a grade (gravity rotated; x uphill), stepping in
/// lock-step with a terrain.
class VehicleCoSim {
 public:
  explicit VehicleCoSim(const RoadSceneParams& p);
  /// The opening exchange (step 0), then the time step: time_step, or time_step_safety x the
  /// smallest critical step of the vehicle's elements and the terrain contact it reported.
  /// Throws ConfigError (naming the scene file and time_step) for a step above that limit.
  void Start(TerrainPort& terrain);
  /// One step; exchanges with the terrain when the step index is a multiple of the interval.
  void Step(TerrainPort& terrain);

  Vehicle& vehicle() { return *vehicle_; }
  const Vehicle& vehicle() const { return *vehicle_; }
  const RoadSceneParams& params() const { return p_; }
  long step() const { return vehicle_->system().step_count(); }
  double time() const { return vehicle_->system().time(); }     ///< since the start of settling
  double driver_time() const { return time() - p_.settle_time; } ///< since the driver's start
  double dt() const { return dt_; }
  const TimeStepLimit& limit() const { return limit_; }
  long settle_steps() const { return settle_steps_; }
  long exchanges() const { return exchanges_; }
  long last_exchange_step() const { return last_exchange_; }
  const std::vector<WheelState>& wheel_states() const { return states_; }
  const std::vector<WheelWrench>& wheel_wrenches() const { return wrenches_; }
  /// Gravity for a grade of `deg` uphill toward +x (the road frame is the slope frame).
  static Eigen::Vector3d GradeGravity(double deg);

 private:
  void Exchange(TerrainPort& terrain);
  RoadSceneParams p_;
  std::unique_ptr<Vehicle> vehicle_;
  double dt_ = 0.0;
  TimeStepLimit limit_;
  long settle_steps_ = 0, exchanges_ = 0, last_exchange_ = -1;
  double checked_stiffness_ = -1.0, checked_damping_ = -1.0;
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
};

/// What a run reports as it goes (the vehicle nodelet publishes from it; the runner prints).
class CoSimObserver {
 public:
  virtual ~CoSimObserver() = default;
  /// After the opening exchange and after every step (the command in force is `cmd`).
  virtual void OnStep(const VehicleCoSim& /*sim*/, const DriveCommand& /*cmd*/) {}
  /// Polled every step: true stops the run (interrupted).
  virtual bool StopRequested() { return false; }
};

/// The scene's loop: settle with the brakes on, then the driver every control period, the terrain
/// every coupling interval, history samples at sample_rate, until the duration or a no-go. A
/// SimulationError (non-finite state, a peer that stopped answering) ends it with result.error set
/// and the history so far; configuration errors throw before the first step.
RoadResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver, CoSimObserver* observer);

/// A terrain model called directly (same process, same thread).
class LocalTerrainPort final : public TerrainPort {
 public:
  explicit LocalTerrainPort(TerrainModel& model) : model_(model) {}
  void Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                std::vector<WheelWrench>* wrenches) override;

 private:
  TerrainModel& model_;
};

/// The scene's speed driver for the vehicle in `vehicle_file` (its mass, wheel radius, driveline
/// reduction and engine curves).
class SceneDriver final : public DriverPort {
 public:
  SceneDriver(const DriverParams& p, const std::string& vehicle_file);
  DriveCommand Exchange(const DriveInput& in) override;

 private:
  std::unique_ptr<Vehicle> vehicle_;  ///< only for its data: never stepped
  SpeedDriver driver_;
};

/// The whole scene in one process: vehicle, terrain model and driver called directly.
class RoadScene {
 public:
  explicit RoadScene(const RoadSceneParams& p);
  RoadResult Run(CoSimObserver* observer = nullptr);
  VehicleCoSim& sim() { return sim_; }
  Vehicle& vehicle() { return sim_.vehicle(); }
  TerrainPort& terrain_port() { return port_; }
  double dt() const { return sim_.dt(); }

 private:
  std::unique_ptr<TerrainModel> terrain_;
  LocalTerrainPort port_;
  SceneDriver driver_;
  VehicleCoSim sim_;
};

/// Writes the result as YAML (speed-made-good, status, timing) to `path`. `status` replaces the
/// detector's status when not empty (error, interrupted); `published` lists message counts by topic.
void WriteRoadResult(const RoadResult& r, const RoadSceneParams& p, const std::string& path,
                     const std::string& status = "",
                     const std::vector<std::pair<std::string, long>>& published = {});
/// Writes the history as CSV to `path`.
void WriteRoadHistory(const RoadResult& r, const std::string& path);

}  // namespace dem_mobility
