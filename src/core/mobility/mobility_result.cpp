#include "dem_mobility/core/mobility/mobility_result.h"

#include <cmath>
#include <fstream>
#include <iomanip>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

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
  f.Set("terrain_model", r.terrain.model);
  f.SetMeasured("cone_index_psi", r.terrain.cone_index);  // (null: a soil given by f with no table at its particle size)
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
