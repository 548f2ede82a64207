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
  p.terrain_file = y.ResolvePath(y.String("terrain"));
  p.grade_deg = y.DoubleIn("grade_deg", -45.0, 45.0);
  p.duration = y.DoubleIn("duration", 1e-3, 3600.0);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 10.0, 0.5);
  if (y.Has("time_step") && y.String("time_step") != "auto") p.time_step = y.DoubleIn("time_step", 1e-7, 1e-2);
  p.time_step_safety = y.DoubleIn("time_step_safety", 0.01, 1.0, 0.5);
  p.coupling_interval = y.Int("coupling_interval", 1);
  if (p.coupling_interval < 1 || p.coupling_interval > 1000)
    y.Fail("coupling_interval", "must be a whole number of steps in [1, 1000], found " + std::to_string(p.coupling_interval));
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

Eigen::Vector3d VehicleCoSim::GradeGravity(double deg) {
  const double a = deg * M_PI / 180.0;
  return 9.81 * Eigen::Vector3d(-std::sin(a), 0.0, -std::cos(a));
}

VehicleCoSim::VehicleCoSim(const RoadSceneParams& p) : p_(p) {
  // the chassis frame at x = 0 with the tires just touching the plane z = 0
  vehicle_ = Vehicle::Load(p.vehicle_file, Eigen::Vector3d::Zero());
  MultibodySystem& sys = vehicle_->system();
  const Eigen::Vector3d shift(0.0, 0.0, vehicle_->design_ride_height());
  for (int i = 1; i < sys.num_bodies(); ++i) sys.mutable_body(i).x += shift;
  sys.set_gravity(GradeGravity(p.grade_deg));
  states_.resize(4);
  wrenches_.resize(4);
}

void VehicleCoSim::Exchange(TerrainPort& terrain) {
  for (int i = 0; i < 4; ++i) states_[i] = vehicle_->GetWheelState(i);
  terrain.Exchange(step(), time(), dt_, states_, &wrenches_);
  DM_THROW_UNLESS(wrenches_.size() == 4, "the terrain answered step ", step(), " with ", wrenches_.size(),
                  " wrenches for 4 wheels");
  for (int i = 0; i < 4; ++i) {
    const WheelWrench& w = wrenches_[i];
    if (!(w.force.allFinite() && w.moment.allFinite()))
      throw SimulationError(detail::Concat("step ", step(), " (t = ", time(), " s): the terrain's wrench on wheel ", i,
                                           " is not finite (force ", w.force.transpose(), ")"));
    vehicle_->SetWheelWrench(i, w);
  }
  ++exchanges_;
  last_exchange_ = step();
  // the contact the terrain reports must stay within the explicit limit of the step in use
  const WheelWrench& w0 = wrenches_[0];
  if (dt_ > 0.0 && (w0.stiffness != checked_stiffness_ || w0.damping != checked_damping_)) {
    const TimeStepLimit c = vehicle_->WheelContactLimit(w0.stiffness, w0.damping);
    if (dt_ > c.dt_crit)
      throw SimulationError(detail::Concat("step ", step(), " (t = ", time(), " s): time step ", dt_,
                                           " s is above the critical step ", c.dt_crit, " s of ", c.element, " (",
                                           c.detail, ")"));
    checked_stiffness_ = w0.stiffness;
    checked_damping_ = w0.damping;
  }
}

void VehicleCoSim::Start(TerrainPort& terrain) {
  DM_DEMAND(dt_ == 0.0);
  Exchange(terrain);
  MultibodySystem& sys = vehicle_->system();
  limit_ = sys.CriticalTimeStep();
  const TimeStepLimit contact = vehicle_->WheelContactLimit(wrenches_[0].stiffness, wrenches_[0].damping);
  if (contact.dt_crit < limit_.dt_crit) limit_ = contact;
  const double dt = p_.time_step > 0.0 ? p_.time_step : p_.time_step_safety * limit_.dt_crit;
  if (!(dt <= limit_.dt_crit))
    throw ConfigError(detail::Concat(p_.file, ": time_step: time step dt = ", dt, " s is above the critical step ",
                                     limit_.dt_crit, " s of ", limit_.element, " (", limit_.detail, "); use dt <= ",
                                     limit_.dt_crit, " s or soften that element"));
  try {
    sys.Finalize(dt);
  } catch (const ConfigError& e) {
    throw ConfigError(p_.file + ": time_step: " + e.what());
  }
  dt_ = dt;
  checked_stiffness_ = wrenches_[0].stiffness;
  checked_damping_ = wrenches_[0].damping;
  settle_steps_ = std::lround(p_.settle_time / dt_);
}

void VehicleCoSim::Step(TerrainPort& terrain) {
  MultibodySystem& sys = vehicle_->system();
  sys.BeginStep();
  if (sys.step_count() % p_.coupling_interval == 0) Exchange(terrain);
  sys.EndStep();
}

void LocalTerrainPort::Exchange(long step, double t, double /*dt*/, const std::vector<WheelState>& states,
                                std::vector<WheelWrench>* wrenches) {
  model_.Compute(step, t, states, wrenches);
}

SceneDriver::SceneDriver(const DriverParams& p, const std::string& vehicle_file)
    : vehicle_(Vehicle::Load(vehicle_file, Eigen::Vector3d::Zero())),
      driver_(p, vehicle_->powertrain(), vehicle_->system().TotalMass(), vehicle_->tire().radius,
              vehicle_->driveline_reduction()) {}

DriveCommand SceneDriver::Exchange(const DriveInput& in) {
  return driver_.Update(in.time, in.period, in.forward_speed, in.drive_shaft_speed);
}

RoadScene::RoadScene(const RoadSceneParams& p)
    : terrain_(LoadTerrainModel(p.terrain_file, p.vehicle_file)),
      port_(*terrain_),
      driver_(p.driver, p.vehicle_file),
      sim_(p) {
  sim_.Start(port_);
}

RoadResult RoadScene::Run(CoSimObserver* observer) { return RunCoSimulation(sim_, port_, driver_, observer); }

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

RoadResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver, CoSimObserver* observer) {
  const RoadSceneParams& p = sim.params();
  RoadResult r;
  r.dt = sim.dt();
  r.dt_crit = sim.limit().dt_crit;
  r.dt_limit_element = sim.limit().element;
  Vehicle& veh = sim.vehicle();
  const double dt = sim.dt();
  const auto wall0 = std::chrono::steady_clock::now();
  const long drive_step = sim.settle_steps();
  const long run_steps = std::lround(p.duration / dt);
  const long sample_every = std::max(1L, std::lround(1.0 / (p.sample_rate * dt)));
  const long control_every = std::max(1L, std::lround(p.driver.control_period / dt));
  DriveCommand cmd;
  cmd.brake_effort = 1.0;  // settling: brakes on, no drive
  double x0 = 0.0;
  try {
    veh.SetBrakeEffort(cmd.brake_effort);
    veh.SetDriveTorqueRequest(0.0);
    if (observer) observer->OnStep(sim, cmd);
    for (;;) {
      const long k = sim.step() - drive_step;  // steps since the driver's start
      if (k >= 0) {
        if (k == 0) x0 = veh.ChassisFramePosition().x();
        const double t = k * dt;
        const double v = veh.ForwardSpeed();
        const double w_ds = veh.DriveShaftSpeed();
        if (k % control_every == 0) {
          DriveInput in;
          in.step = sim.step();
          in.time = t;
          in.period = control_every * dt;
          in.forward_speed = v;
          in.drive_shaft_speed = w_ds;
          cmd = driver.Exchange(in);
          ++r.driver_updates;
          veh.SetDriveTorqueRequest(cmd.drive_torque);
          veh.SetBrakeEffort(cmd.brake_effort);
        }
        if (k % sample_every == 0) {
          r.history.push_back({t, veh.ChassisFramePosition().x() - x0, v, cmd.speed_command, w_ds,
                               veh.AppliedDriveTorque(), cmd.brake_effort, cmd.wot_limited});
          if (t >= p.plateau.stall_time && v < p.plateau.stall_speed && cmd.speed_command > p.plateau.stall_speed) {
            r.ended_early = true;
            break;
          }
        }
        if (k >= run_steps) break;
      }
      if (observer && observer->StopRequested()) {
        r.interrupted = true;
        break;
      }
      sim.Step(terrain);
      if (observer) observer->OnStep(sim, cmd);
    }
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  r.steps = sim.step();
  r.exchanges = sim.exchanges();
  r.sim_time = r.history.empty() ? 0.0 : r.history.back().t;
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  r.smg = DetectSpeedMadeGood(r.history, p.plateau, p.driver.v_max);
  return r;
}

void WriteRoadResult(const RoadResult& r, const RoadSceneParams& p, const std::string& path, const std::string& status,
                     const std::vector<std::pair<std::string, long>>& published) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "scene" << YAML::Value << p.file;
  e << YAML::Key << "grade_deg" << YAML::Value << p.grade_deg;
  e << YAML::Key << "speed_made_good" << YAML::Value << r.smg.value;
  e << YAML::Key << "speed_made_good_mph" << YAML::Value << r.smg.value / 0.44704;
  e << YAML::Key << "status" << YAML::Value << (status.empty() ? r.smg.status : status);
  e << YAML::Key << "window_slope" << YAML::Value << r.smg.window_slope;
  e << YAML::Key << "window_speed_std" << YAML::Value << r.smg.window_std;
  e << YAML::Key << "ended_early" << YAML::Value << r.ended_early;
  e << YAML::Key << "time_step" << YAML::Value << r.dt;
  e << YAML::Key << "critical_time_step" << YAML::Value << r.dt_crit;
  e << YAML::Key << "critical_element" << YAML::Value << r.dt_limit_element;
  e << YAML::Key << "coupling_interval" << YAML::Value << p.coupling_interval;
  e << YAML::Key << "steps" << YAML::Value << r.steps;
  e << YAML::Key << "exchanges" << YAML::Value << r.exchanges;
  e << YAML::Key << "driver_updates" << YAML::Value << r.driver_updates;
  e << YAML::Key << "simulated_time" << YAML::Value << r.sim_time;
  e << YAML::Key << "wall_time" << YAML::Value << r.wall_time;
  e << YAML::Key << "real_time_factor" << YAML::Value << (r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0);
  e << YAML::Key << "interrupted" << YAML::Value << r.interrupted;
  e << YAML::Key << "error" << YAML::Value << r.error;
  if (!published.empty()) {
    e << YAML::Key << "published" << YAML::Value << YAML::BeginMap;
    for (const auto& [topic, n] : published) e << YAML::Key << topic << YAML::Value << n;
    e << YAML::EndMap;
  }
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
