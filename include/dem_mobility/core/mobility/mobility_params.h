// A mobility run's parameters (paper sections 4.3 and 6): the vehicle accelerates up a grade on a
// terrain (the rigid road, or DEM soil of a given cone index) and the run reports its
// speed-made-good; the settings of the detector that judges it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/vehicle/driver.h"

namespace dem_mobility::core {

class YamlReader;

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

}  // namespace dem_mobility::core
