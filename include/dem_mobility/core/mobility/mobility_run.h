// A mobility run (paper sections 4.3 and 6): the vehicle accelerates up a grade on a terrain (the
// rigid road, or DEM soil of a given cone index), and the run reports its speed-made-good. These
// are the run's parameters, history and result, and the detector that judges the speed history;
// the loop that produces them is the co-simulation's (cosim/cosim_loop.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/cosim/exchange.h"
#include "dem_mobility/core/vehicle/driver.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;
class TerrainModel;

/// Settings of the speed-made-good detector.
struct PlateauParams {
  double window = 5.0;        ///< [s] trailing window the steady state is judged on
  double tolerance = 0.05;    ///< [m/s^2] largest |dv/dt| in the window that counts as steady
  double scatter = 0.1;       ///< largest rms speed about the window's fitted line, over its mean speed
  /// [m/s^2] largest |dv/dt| over the window's trailing half (a rise and then a fall fit a flat
  /// line over the whole window: the speed must not be falling or rising at the end)
  double end_tolerance = 0.1;
  /// the least share of the window's samples at full throttle (the driver's torque capped by the
  /// WOT curve) for a plateau below the command to be the speed-made-good: it is the steady speed
  /// with the engine giving all the torque it has at that speed (paper section 4.3). A plateau
  /// with the engine held back is the driver's, not the vehicle's limit
  double full_throttle = 0.5;
  double stall_speed = 0.2;   ///< [m/s] below this for stall_time (while the command is above it): no-go
  double stall_time = 5.0;    ///< [s]
};

struct MobilityRunParams {
  std::string file;           ///< the scene file (for messages)
  std::string kind = "road_slope";  ///< its `scene:` (road_slope or soil_slope: the same run)
  std::string vehicle_file, terrain_file;
  /// key=value overrides of the terrain file (the scene's terrain_overrides map: a soil's
  /// cone_index, fidelity, threads, seed)
  std::vector<std::string> terrain_overrides;
  double grade_deg = 0.0;
  /// [deg] a side slope across the grade: the left (+y) side higher, gravity pulling to -y
  double side_slope_deg = 0.0;
  /// [m] the vehicle starts this high above its resting place (a drop onto the terrain)
  double start_height = 0.0;
  /// [m/s] the vehicle starts rolling at this speed along x, every shaft and wheel turning with
  /// it (Vehicle::SetRollingSpeed): a vehicle arriving on the terrain at speed
  double start_speed = 0.0;
  double duration = 40.0;
  double settle_time = 0.5;   ///< [s] brakes on, driver off, before the driver's t = 0
  double time_step = 0.0;     ///< 0: auto = time_step_safety x critical step
  double time_step_safety = 0.9;  // of the guard's bound (MultibodySystem::CriticalTimeStep)
  /// `time_step_guard: false`: a time_step above the critical step runs (stability studies only:
  /// docs/stability.md); the result says so
  bool time_step_guard = true;
  int coupling_interval = 1;  ///< vehicle steps per terrain exchange (wrenches held in between)
  DriverParams driver;
  PlateauParams plateau;
  double sample_rate = 100.0; ///< [Hz] history samples
  bool end_when_steady = false;  ///< end the run once the detector finds a plateau or the command reached
  /// Reads a scene file of kind `road_slope` or `soil_slope`; ConfigError names the file and key.
  static MobilityRunParams Read(const YamlReader& y);
  /// Gravity in the slope frame (x uphill, z the terrain's normal): the grade about y, the side
  /// slope about x.
  Eigen::Vector3d Gravity() const;
};

/// One history sample (t from the driver's start).
struct MobilitySample {
  using StateBulk = void;  // (a checkpoint copies it as bytes: common/state_archive.h)
  double t, x, speed, speed_command, drive_shaft_speed, drive_torque, brake_effort;
  bool wot_limited;
  std::array<double, kWheels> slip{};     ///< 1 - v / (omega r) per wheel (0 while omega r < 0.05 m/s)
  std::array<double, kWheels> sinkage{};  ///< [m] per wheel, as the terrain reports it
  double traction = 0.0;  ///< the terrain's pull on the wheels along the slope [N]
  double thrust = 0.0;    ///< drive torque at the wheels over the tire radius [N]
  double y = 0.0;         ///< [m] the chassis frame's lateral offset from the start (+ left)
  double heading = 0.0;   ///< [rad] the chassis x axis's yaw from the start (+ to the left)
};

struct SpeedMadeGood {
  double value = 0.0;       ///< [m/s]
  std::string status;       ///< steady | command_limited | no_go | not_steady
  double window_slope = 0.0;///< dv/dt over the judging window [m/s^2]
  double window_std = 0.0;  ///< speed standard deviation in the window [m/s]
  double end_slope = 0.0;   ///< dv/dt over the window's trailing half [m/s^2]
  template <class Ar>
  void Io(Ar& ar) {
    ar(value, status, window_slope, window_std, end_slope);
  }
};

/// How long the vehicle has been stalled at the end of the history [s]: the time since the last
/// sample at which it moved at `stall_speed` or more, or at which the command was not above
/// `stall_speed` yet (a vehicle the driver has not asked to move is not stuck); 0 if it moves now.
double StalledFor(const std::vector<MobilitySample>& h, double stall_speed);

/// Judges the speed history: a plateau under full throttle, the command reached, or a stall
/// (stalled for `stall_time`: no-go).
SpeedMadeGood DetectSpeedMadeGood(const std::vector<MobilitySample>& h, const PlateauParams& p, double v_max);

/// Means over the detector's judging window (the steady state).
struct SteadyFigures {
  using StateBulk = void;
  int samples = 0;
  std::array<double, kWheels> slip{}, sinkage{};
  double traction_coefficient = 0.0;   ///< terrain pull / (m g cos(grade) cos(side slope))
  double motion_resistance = 0.0;      ///< (thrust - pull) / (m g cos(grade) cos(side slope))
  double drawbar_margin = 0.0;         ///< traction_coefficient - tan(grade)
};

struct MobilityRunResult {
  SpeedMadeGood smg;
  SteadyFigures steady;
  TerrainDescription terrain;  ///< what ran (model, cone index, time step, fidelity)
  std::vector<MobilitySample> history;
  std::string terrain_model;  ///< the terrain that ran (its `model:`)
  double cone_index = std::numeric_limits<double>::quiet_NaN();  ///< its soil strength [psi]
  double dt = 0.0, dt_crit = 0.0;
  std::string dt_limit_element;
  int coupling_interval = 1;  ///< vehicle steps per exchange in use
  /// The vehicle's energy ledger at the end, and followed along the run (every history sample's
  /// step, settling included, from the first step on)
  EnergyReport vehicle_energy;
  LedgerWatch vehicle_ledger;
  long steps = 0, exchanges = 0, driver_updates = 0;
  double sim_time = 0.0, wall_time = 0.0;  ///< sim_time: from the driver's start
  bool ended_early = false;
  bool interrupted = false; ///< stopped from outside (shutdown) before the end
  std::string error;        ///< empty on success
  /// error | interrupted | the detector's status.
  std::string Status() const;
  /// What a checkpoint keeps of a run under way (common/state_archive.h): the history, the
  /// ledger and the counts (the rest is set again when it ends).
  template <class Ar>
  void Io(Ar& ar) {
    ar(history, vehicle_ledger, driver_updates, wall_time, ended_early);
  }
};

/// The steady figures over the trailing `window` of the history (vehicle mass m, grade).
SteadyFigures SteadyWindowFigures(const std::vector<MobilitySample>& h, double window, double mass, double grade_deg,
                                  double side_slope_deg = 0.0);

/// The run's result file (speed-made-good, status, terrain, timing); `published` lists message
/// counts by topic (the ROS run's); `terrain`: the terrain model that ran, when in this process
/// (its own figures: soil, level, patch checks).
ResultFile MobilityResultFile(const MobilityRunResult& r, const MobilityRunParams& p,
                              const std::vector<std::pair<std::string, long>>& published = {},
                              const TerrainModel* terrain = nullptr);
/// Writes the history as CSV to `path`.
void WriteMobilityHistory(const MobilityRunResult& r, const std::string& path);

}  // namespace dem_mobility::core
