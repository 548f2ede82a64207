#include "dem_mobility/core/scenes/road_scene.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility {

RoadSceneParams RoadSceneParams::Read(const YamlReader& y) {
  RoadSceneParams p;
  p.file = y.file();
  const std::string scene = y.String("scene");
  if (scene != "road_slope") y.Fail("scene", "expected 'road_slope', found '" + scene + "'");
  p.vehicle_file = y.ResolvePath(y.String("vehicle"));
  p.grade_deg = y.DoubleIn("grade_deg", -45.0, 45.0);
  p.duration = y.DoubleIn("duration", 1e-3, 3600.0);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 10.0, 0.5);
  if (y.Has("time_step") && y.String("time_step") != "auto") p.time_step = y.DoubleIn("time_step", 1e-7, 1e-2);
  p.time_step_safety = y.DoubleIn("time_step_safety", 0.01, 1.0, 0.5);
  const YamlReader road = y.Child("road");
  p.road_length = road.Positive("length");
  p.road_width = road.DoubleIn("width", 3.0, 1000.0);
  p.road_cell = road.Positive("cell");
  p.road_start = road.Double("start_x");
  road.Finish();
  const YamlReader tc = y.Child("tire_contact");
  p.tire_contact = ContactParams::Read(tc);
  tc.Finish();
  p.driver = DriverParams::Read(y.Child("driver"));
  const YamlReader res = y.Child("result");
  p.sample_rate = res.DoubleIn("sample_rate", 1.0, 1e5, 100.0);
  p.plateau.window = res.DoubleIn("plateau_window", 0.5, 60.0, 5.0);
  p.plateau.tolerance = res.Positive("plateau_tolerance", 0.05);
  p.plateau.stall_speed = res.Positive("stall_speed", 0.2);
  p.plateau.stall_time = res.Positive("stall_time", 5.0);
  res.Finish();
  y.Finish();
  return p;
}

Eigen::Vector3d RoadScene::GradeGravity(double deg) {
  const double a = deg * M_PI / 180.0;
  return 9.81 * Eigen::Vector3d(-std::sin(a), 0.0, -std::cos(a));
}

RoadScene::RoadScene(const RoadSceneParams& p) : p_(p) {
  terrain_ = std::make_unique<TerrainMesh>(MakeFlatRoad(p.road_start, p.road_length, p.road_width, p.road_cell),
                                           p.road_cell, 0.05);
  vehicle_ = Vehicle::Load(p.vehicle_file, terrain_.get(), p.tire_contact, Eigen::Vector3d::Zero());
  // place the chassis frame so that the tires just touch the road at the start
  const Eigen::Vector3d shift(p.road_start + 10.0, 0.0, vehicle_->design_ride_height());
  MultibodySystem& sys = vehicle_->system();
  for (int i = 1; i < sys.num_bodies(); ++i) sys.mutable_body(i).x += shift;
  sys.set_gravity(GradeGravity(p.grade_deg));
  limit_ = sys.CriticalTimeStep();
  dt_ = p.time_step > 0.0 ? p.time_step : p.time_step_safety * limit_.dt_crit;
  try {
    sys.Finalize(dt_);
  } catch (const ConfigError& e) {
    throw ConfigError(p.file + ": time_step: " + e.what());
  }
}

SpeedMadeGood DetectSpeedMadeGood(const std::vector<RoadSample>& h, const PlateauParams& p, double v_max) {
  SpeedMadeGood s;
  if (h.empty()) {
    s.status = "not_steady";
    return s;
  }
  const double t_end = h.back().t;
  if (t_end >= p.stall_time && h.back().speed < p.stall_speed) {
    s.status = "no_go";
    return s;
  }
  // least-squares slope and mean over the trailing window
  double n = 0, st = 0, sv = 0, stt = 0, stv = 0, svv = 0;
  bool limited = false;
  for (auto it = h.rbegin(); it != h.rend() && it->t >= t_end - p.window; ++it) {
    n += 1;
    st += it->t;
    sv += it->speed;
    stt += it->t * it->t;
    stv += it->t * it->speed;
    svv += it->speed * it->speed;
    limited = limited || it->wot_limited;
  }
  const double mean = sv / n;
  const double var_t = stt / n - (st / n) * (st / n);
  s.window_slope = var_t > 0 ? (stv / n - (st / n) * mean) / var_t : 0.0;
  s.window_std = std::sqrt(std::max(0.0, svv / n - mean * mean));
  s.value = mean;
  if (t_end < p.window) {
    s.status = "not_steady";
  } else if (std::abs(s.window_slope) > p.tolerance) {
    s.status = "not_steady";
  } else if (!limited && mean >= 0.98 * v_max) {
    s.status = "command_limited";
  } else {
    s.status = "steady";
  }
  return s;
}

RoadResult RoadScene::Run(const ProgressFn& progress) {
  RoadResult r;
  r.dt = dt_;
  r.dt_crit = limit_.dt_crit;
  r.dt_limit_element = limit_.element;
  MultibodySystem& sys = vehicle_->system();
  Vehicle& veh = *vehicle_;
  SpeedDriver driver(p_.driver, veh.powertrain(), sys.TotalMass(), veh.tire().radius, veh.driveline_reduction());
  const auto wall0 = std::chrono::steady_clock::now();
  auto wall = [&wall0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  };
  const long settle_steps = std::lround(p_.settle_time / dt_);
  const long run_steps = std::lround(p_.duration / dt_);
  const long sample_every = std::max(1L, std::lround(1.0 / (p_.sample_rate * dt_)));
  double next_progress = 1.0;
  try {
    veh.SetBrakeEffort(1.0);
    veh.SetDriveTorqueRequest(0.0);
    for (long i = 0; i < settle_steps; ++i) sys.Step();
    const double x0 = veh.ChassisFramePosition().x();
    for (long i = 0; i <= run_steps; ++i) {
      const double t = i * dt_;
      const double v = veh.ForwardSpeed();
      const double w_ds = veh.DriveShaftSpeed();
      const DriverCommand cmd = driver.Update(t, dt_, v, w_ds);
      veh.SetDriveTorqueRequest(cmd.drive_torque);
      veh.SetBrakeEffort(cmd.brake_effort);
      if (i % sample_every == 0) {
        r.history.push_back({t, veh.ChassisFramePosition().x() - x0, v, cmd.speed_command, w_ds,
                             veh.AppliedDriveTorque(), cmd.brake_effort, cmd.wot_limited});
        if (t >= p_.plateau.stall_time && v < p_.plateau.stall_speed && cmd.speed_command > p_.plateau.stall_speed) {
          r.ended_early = true;
          break;
        }
      }
      if (i == run_steps) break;
      sys.Step();
      if (progress && wall() >= next_progress) {
        progress(t, p_.duration, v, wall());
        next_progress += 1.0;
      }
    }
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  r.steps = sys.step_count();
  r.sim_time = r.history.empty() ? 0.0 : r.history.back().t;
  r.wall_time = wall();
  r.smg = DetectSpeedMadeGood(r.history, p_.plateau, p_.driver.v_max);
  return r;
}

void WriteRoadResult(const RoadResult& r, const RoadSceneParams& p, const std::string& path) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "scene" << YAML::Value << p.file;
  e << YAML::Key << "grade_deg" << YAML::Value << p.grade_deg;
  e << YAML::Key << "speed_made_good" << YAML::Value << r.smg.value;
  e << YAML::Key << "speed_made_good_mph" << YAML::Value << r.smg.value / 0.44704;
  e << YAML::Key << "status" << YAML::Value << r.smg.status;
  e << YAML::Key << "window_slope" << YAML::Value << r.smg.window_slope;
  e << YAML::Key << "window_speed_std" << YAML::Value << r.smg.window_std;
  e << YAML::Key << "ended_early" << YAML::Value << r.ended_early;
  e << YAML::Key << "time_step" << YAML::Value << r.dt;
  e << YAML::Key << "critical_time_step" << YAML::Value << r.dt_crit;
  e << YAML::Key << "critical_element" << YAML::Value << r.dt_limit_element;
  e << YAML::Key << "steps" << YAML::Value << r.steps;
  e << YAML::Key << "simulated_time" << YAML::Value << r.sim_time;
  e << YAML::Key << "wall_time" << YAML::Value << r.wall_time;
  e << YAML::Key << "real_time_factor" << YAML::Value << (r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0);
  e << YAML::Key << "error" << YAML::Value << r.error;
  e << YAML::EndMap;
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the result file");
  out << e.c_str() << "\n";
}

void WriteRoadHistory(const RoadResult& r, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the history file");
  out << "t,x,speed,speed_command,drive_shaft_speed,drive_torque,brake_effort,wot_limited\n";
  out << std::setprecision(8);
  for (const auto& s : r.history)
    out << s.t << "," << s.x << "," << s.speed << "," << s.speed_command << "," << s.drive_shaft_speed << ","
        << s.drive_torque << "," << s.brake_effort << "," << s.wot_limited << "\n";
}

}  // namespace dem_mobility
