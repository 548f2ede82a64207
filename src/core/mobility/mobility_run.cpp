#include "dem_mobility/core/mobility/mobility_run.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

MobilityRunParams MobilityRunParams::Read(const YamlReader& y) {
  MobilityRunParams p;
  p.file = y.file();
  const std::string scene = y.String("scene");
  if (scene != "road_slope" && scene != "soil_slope")
    y.Fail("scene", "expected 'road_slope' or 'soil_slope', found '" + scene + "'");
  p.kind = scene;
  p.vehicle_file = y.ResolvePath(y.String("vehicle"));
  p.terrain_file = y.ResolvePath(y.String("terrain"));
  if (y.Has("terrain_overrides")) {
    // (nested maps, as `terrain_overrides.levels.tiny.length=6` on the command line makes them,
    // stand for dotted keys of the terrain file)
    const std::function<void(const YamlReader&, const std::string&)> flatten = [&](const YamlReader& o,
                                                                                   const std::string& prefix) {
      for (const std::string& k : o.Keys()) {
        if (o.IsMap(k))
          flatten(o.Child(k), prefix + k + ".");
        else if (o.IsList(k))  // (terrain_overrides.patch.check_window=[0.3,0.7])
          p.terrain_overrides.push_back(prefix + k + "=" + o.FlowText(k));
        else if (!o.Has(k))  // null (terrain_overrides.cone_index=~: the file's cone index unset, f given instead)
          p.terrain_overrides.push_back(prefix + k + "=~");
        else
          p.terrain_overrides.push_back(prefix + k + "=" + o.String(k));
      }
      o.Finish();
    };
    flatten(y.Child("terrain_overrides"), "");
  }
  p.grade_deg = y.DoubleIn("grade_deg", -45.0, 45.0);
  p.side_slope_deg = y.DoubleIn("side_slope_deg", -45.0, 45.0, 0.0);
  p.start_height = y.DoubleIn("start_height", 0.0, 5.0, 0.0);
  p.start_speed = y.DoubleIn("start_speed", 0.0, 40.0, 0.0);
  p.duration = y.DoubleIn("duration", 1e-3, 3600.0);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 10.0, 0.5);
  if (y.Has("time_step") && y.String("time_step") != "auto") p.time_step = y.DoubleIn("time_step", 1e-7, 1e-2);
  p.time_step_safety = y.DoubleIn("time_step_safety", 0.01, 1.0, 0.9);
  p.time_step_guard = y.Bool("time_step_guard", true);
  p.coupling_interval = y.Int("coupling_interval", 1);
  if (p.coupling_interval < 1 || p.coupling_interval > 1000)
    y.Fail("coupling_interval", "must be a whole number of steps in [1, 1000], found " + std::to_string(p.coupling_interval));
  p.driver = DriverParams::Read(y.Child("driver"));
  const YamlReader res = y.Child("result");
  p.sample_rate = res.DoubleIn("sample_rate", 1.0, 1e5, 100.0);
  p.plateau.window = res.DoubleIn("plateau_window", 0.5, 60.0, 5.0);
  p.plateau.tolerance = res.Positive("plateau_tolerance", 0.05);
  p.plateau.scatter = res.Positive("plateau_scatter", 0.1);
  p.plateau.end_tolerance = res.Positive("plateau_end_tolerance", 0.1);
  p.plateau.full_throttle = res.DoubleIn("plateau_full_throttle", 0.01, 1.0, 0.5);
  p.plateau.stall_speed = res.Positive("stall_speed", 0.2);
  p.plateau.stall_time = res.Positive("stall_time", 5.0);
  p.end_when_steady = res.Bool("end_when_steady", false);
  res.Finish();
  y.Finish();
  return p;
}

Eigen::Vector3d MobilityRunParams::Gravity() const {
  const double a = grade_deg * M_PI / 180.0, b = side_slope_deg * M_PI / 180.0;
  return 9.81 * Eigen::Vector3d(-std::sin(a), -std::cos(a) * std::sin(b), -std::cos(a) * std::cos(b));
}

double StalledFor(const std::vector<MobilitySample>& h, double stall_speed) {
  if (h.empty()) return 0.0;
  for (auto it = h.rbegin(); it != h.rend(); ++it)
    if (it->speed >= stall_speed || it->speed_command <= stall_speed) return h.back().t - it->t;
  return h.back().t - h.front().t;
}

namespace {

/// The least-squares slope of speed against time over the samples from t0 on (0 for fewer than two).
double TrailingSlope(const std::vector<MobilitySample>& h, double t0) {
  double n = 0, st = 0, sv = 0, stt = 0, stv = 0;
  for (auto it = h.rbegin(); it != h.rend() && it->t >= t0; ++it) {
    n += 1;
    st += it->t;
    sv += it->speed;
    stt += it->t * it->t;
    stv += it->t * it->speed;
  }
  if (n < 2) return 0.0;
  const double var_t = stt / n - (st / n) * (st / n);
  return var_t > 0 ? (stv / n - (st / n) * (sv / n)) / var_t : 0.0;
}

}  // namespace

SpeedMadeGood DetectSpeedMadeGood(const std::vector<MobilitySample>& h, const PlateauParams& p, double v_max) {
  SpeedMadeGood s;
  if (h.empty()) {
    s.status = "not_steady";
    return s;
  }
  const double t_end = h.back().t;
  if (StalledFor(h, p.stall_speed) >= p.stall_time) {
    s.status = "no_go";
    return s;
  }
  // least-squares slope and mean over the trailing window
  double n = 0, st = 0, sv = 0, stt = 0, stv = 0, svv = 0, at_wot = 0;
  for (auto it = h.rbegin(); it != h.rend() && it->t >= t_end - p.window; ++it) {
    n += 1;
    st += it->t;
    sv += it->speed;
    stt += it->t * it->t;
    stv += it->t * it->speed;
    svv += it->speed * it->speed;
    at_wot += it->wot_limited ? 1 : 0;
  }
  const double mean = sv / n;
  const double var_t = stt / n - (st / n) * (st / n);
  s.window_slope = var_t > 0 ? (stv / n - (st / n) * mean) / var_t : 0.0;
  s.window_std = std::sqrt(std::max(0.0, svv / n - mean * mean));
  // the scatter about the fitted line: a rise and a fall within the window fit a flat line too
  s.end_slope = TrailingSlope(h, t_end - 0.5 * p.window);
  const double residual = std::sqrt(std::max(0.0, svv / n - mean * mean - s.window_slope * s.window_slope * var_t));
  s.value = mean;
  if (t_end < p.window || mean < p.stall_speed) {  // (under the stall speed: a stall, if it lasts)
    s.status = "not_steady";
  } else if (std::abs(s.window_slope) > p.tolerance || residual > p.scatter * std::abs(mean) ||
             std::abs(s.end_slope) > p.end_tolerance) {
    s.status = "not_steady";
  } else if (at_wot >= p.full_throttle * n) {
    s.status = "steady";  // level, with the engine at full torque for its speed
  } else if (mean >= 0.98 * v_max) {
    s.status = "command_limited";
  } else {
    // level below the command with the engine held back (the driver's controller, not the
    // vehicle, sets this speed): no speed-made-good yet
    s.status = "not_steady";
  }
  return s;
}

SteadyFigures SteadyWindowFigures(const std::vector<MobilitySample>& h, double window, double mass, double grade_deg,
                                  double side_slope_deg) {
  SteadyFigures f;
  if (h.empty()) return f;
  const double a = grade_deg * M_PI / 180.0, wn = mass * 9.81 * std::cos(a) * std::cos(side_slope_deg * M_PI / 180.0);
  const double t_end = h.back().t;
  double pull = 0.0, thrust = 0.0;
  for (auto it = h.rbegin(); it != h.rend() && it->t >= t_end - window; ++it) {
    ++f.samples;
    for (int i = 0; i < kWheels; ++i) {
      f.slip[i] += it->slip[i];
      f.sinkage[i] += it->sinkage[i];
    }
    pull += it->traction;
    thrust += it->thrust;
  }
  for (int i = 0; i < kWheels; ++i) {
    f.slip[i] /= f.samples;
    f.sinkage[i] /= f.samples;
  }
  f.traction_coefficient = pull / f.samples / wn;
  f.motion_resistance = (thrust - pull) / f.samples / wn;
  f.drawbar_margin = f.traction_coefficient - std::tan(a);
  return f;
}

std::string MobilityRunResult::Status() const {
  if (!error.empty()) return "error";
  if (interrupted) return "interrupted";
  return smg.status;
}

ResultFile MobilityResultFile(const MobilityRunResult& r, const MobilityRunParams& p,
                              const std::vector<std::pair<std::string, long>>& published, const TerrainModel* terrain) {
  ResultFile f(p.file, p.kind);
  f.SetStatus(r.Status(), r.error);
  f.Set("grade_deg", p.grade_deg);
  if (p.side_slope_deg != 0.0) f.Set("side_slope_deg", p.side_slope_deg);
  if (p.start_height != 0.0) f.Set("start_height", p.start_height);
  if (p.start_speed != 0.0) f.Set("start_speed", p.start_speed);
  if (!p.time_step_guard) f.Set("time_step_guard", false);
  f.Set("terrain", p.terrain_file);
  f.Set("terrain_model", r.terrain_model);
  f.SetMeasured("cone_index_psi", r.cone_index);  // (null: a soil given by f with no table at its particle size)
  if (!r.terrain.fidelity.empty()) f.Set("fidelity", r.terrain.fidelity);
  f.Set("speed_made_good", r.smg.value);
  f.Set("speed_made_good_mph", r.smg.value / 0.44704);
  f.Set("verdict", r.smg.status);
  f.Set("window_slope", r.smg.window_slope);
  f.Set("window_speed_std", r.smg.window_std);
  f.Set("window_end_slope", r.smg.end_slope);
  f.Set("ended_early", r.ended_early);
  const SteadyFigures& s = r.steady;
  f.Set("window_samples", s.samples);
  f.SetFlow("slip", std::vector<double>(s.slip.begin(), s.slip.end()));
  f.SetFlow("sinkage", std::vector<double>(s.sinkage.begin(), s.sinkage.end()));
  f.Set("traction_coefficient", s.traction_coefficient);
  f.Set("motion_resistance_coefficient", s.motion_resistance);
  f.Set("drawbar_margin", s.drawbar_margin);
  f.Set("time_step", r.dt);
  f.Set("critical_time_step", r.dt_crit);
  f.Set("critical_element", r.dt_limit_element);
  f.Set("coupling_interval", r.coupling_interval);
  f.Set("steps", r.steps);
  f.Set("exchanges", r.exchanges);
  f.Set("driver_updates", r.driver_updates);
  f.Set("simulated_time", r.sim_time);
  f.Set("wall_time", r.wall_time);
  f.Set("real_time_factor", r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0);
  f.Set("interrupted", r.interrupted);
  // the vehicle's energy ledger (Vehicle::Energy): what the terrain and the engine put in, what the
  // dampers, brakes and differentials took; followed along the run (docs/stability.md)
  const EnergyReport& e = r.vehicle_energy;
  const LedgerWatch& w = r.vehicle_ledger;
  f.Set("vehicle_energy_kinetic", e.kinetic);
  f.Set("vehicle_energy_terrain_work", e.wall_work);
  f.Set("vehicle_energy_engine_work", e.exchanged);
  f.SetLedger("vehicle_energy", w);
  if (!published.empty()) f.SetCounts("published", published);
  if (terrain) terrain->Describe(&f);
  return f;
}

void WriteMobilityHistory(const MobilityRunResult& r, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the history file");
  out << "t,x,speed,speed_command,drive_shaft_speed,drive_torque,brake_effort,wot_limited,traction,thrust,y,heading";
  for (const char* w : kWheelNames) out << ",slip_" << w;
  for (const char* w : kWheelNames) out << ",sinkage_" << w;
  out << "\n" << std::setprecision(8);
  for (const auto& s : r.history) {
    out << s.t << "," << s.x << "," << s.speed << "," << s.speed_command << "," << s.drive_shaft_speed << ","
        << s.drive_torque << "," << s.brake_effort << "," << s.wot_limited << "," << s.traction << "," << s.thrust
        << "," << s.y << "," << s.heading;
    for (double v : s.slip) out << "," << v;
    for (double v : s.sinkage) out << "," << v;
    out << "\n";
  }
  out.flush();
  if (!out) throw ConfigError(path + ": writing the history file failed (disk full or a file size limit?)");
}

}  // namespace dem_mobility::core
