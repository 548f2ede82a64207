// A mobility run (paper sections 4.3 and 6): the vehicle accelerates up a grade on a terrain (the
// rigid road, or DEM soil of a given cone index), and the run reports its speed-made-good. These
// are the run's parameters, history and result, and the detector that judges the speed history;
// the loop that produces them is the co-simulation's (cosim/cosim_loop.h).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/vehicle/driver.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;

/// Settings of the speed-made-good detector.
struct PlateauParams {
  double window = 5.0;        ///< [s] trailing window the steady state is judged on
  double tolerance = 0.05;    ///< [m/s^2] largest |dv/dt| in the window that counts as steady
  double stall_speed = 0.2;   ///< [m/s] below this after stall_time: no-go
  double stall_time = 5.0;    ///< [s]
};

struct MobilityRunParams {
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
  /// Reads a scene file of kind `road_slope`; ConfigError names the file and key.
  static MobilityRunParams Read(const YamlReader& y);
};

/// One history sample (t from the driver's start).
struct MobilitySample {
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
SpeedMadeGood DetectSpeedMadeGood(const std::vector<MobilitySample>& h, const PlateauParams& p, double v_max);

struct MobilityRunResult {
  SpeedMadeGood smg;
  std::vector<MobilitySample> history;
  std::string terrain_model;  ///< the terrain that ran (its `model:`)
  double cone_index = std::numeric_limits<double>::quiet_NaN();  ///< its soil strength [psi]
  double dt = 0.0, dt_crit = 0.0;
  std::string dt_limit_element;
  long steps = 0, exchanges = 0, driver_updates = 0;
  double sim_time = 0.0, wall_time = 0.0;  ///< sim_time: from the driver's start
  bool ended_early = false;
  bool interrupted = false; ///< stopped from outside (shutdown) before the end
  std::string error;        ///< empty on success
  /// error | interrupted | the detector's status.
  std::string Status() const;
};

/// The run's result file (speed-made-good, status, terrain, timing); `published` lists message
/// counts by topic (the ROS run's).
ResultFile MobilityResultFile(const MobilityRunResult& r, const MobilityRunParams& p,
                              const std::vector<std::pair<std::string, long>>& published = {});
/// Writes the history as CSV to `path`.
void WriteMobilityHistory(const MobilityRunResult& r, const std::string& path);

}  // namespace dem_mobility::core
