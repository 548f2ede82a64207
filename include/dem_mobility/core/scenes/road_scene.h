// The paper's vehicle-on-road scene (CI = 300 case): the vehicle on a rigid polygonal road at a
// grade, commanded to accelerate at 1 m/s^2 toward 25 m/s; the result is the speed-made-good.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/multibody/contact.h"
#include "dem_mobility/core/multibody/trimesh.h"
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
  std::string vehicle_file;
  double grade_deg = 0.0;
  double duration = 40.0;
  double settle_time = 0.5;   ///< [s] brakes on, driver off, before t = 0
  double time_step = 0.0;     ///< 0: auto = time_step_safety x critical step
  double time_step_safety = 0.5;
  double road_length = 0.0, road_width = 0.0, road_cell = 0.0, road_start = 0.0;
  ContactParams tire_contact;
  DriverParams driver;
  PlateauParams plateau;
  double sample_rate = 100.0; ///< [Hz] history samples
  static RoadSceneParams Read(const YamlReader& y);
};

/// One history sample.
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
  long steps = 0;
  double sim_time = 0.0, wall_time = 0.0;
  bool ended_early = false;
  std::string error;        ///< empty on success
};

/// Progress report callback: (sim time, duration, speed, wall seconds so far).
using ProgressFn = std::function<void(double, double, double, double)>;

class RoadScene {
 public:
  explicit RoadScene(const RoadSceneParams& p);
  /// Runs the whole scene. Numerical failures are caught and returned in result.error with the
  /// history so far; configuration errors throw before anything runs.
  RoadResult Run(const ProgressFn& progress = nullptr);
  Vehicle& vehicle() { return *vehicle_; }
  const TerrainMesh& terrain() const { return *terrain_; }
  double dt() const { return dt_; }
  /// Gravity for a grade of `deg` uphill toward +x (the road frame is the slope frame).
  static Eigen::Vector3d GradeGravity(double deg);

 private:
  RoadSceneParams p_;
  std::unique_ptr<TerrainMesh> terrain_;
  std::unique_ptr<Vehicle> vehicle_;
  double dt_ = 0.0;
  TimeStepLimit limit_;
};

/// Writes the result as YAML (speed-made-good, status, timing) to `path`.
void WriteRoadResult(const RoadResult& r, const RoadSceneParams& p, const std::string& path);
/// Writes the history as CSV to `path`.
void WriteRoadHistory(const RoadResult& r, const std::string& path);

}  // namespace dem_mobility
