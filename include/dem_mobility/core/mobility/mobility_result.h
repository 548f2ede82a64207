// A mobility run (paper sections 4.3 and 6): the vehicle accelerates up a grade on a terrain (the
// rigid road, or DEM soil of a given cone index), and the run reports its speed-made-good. These
// are the run's parameters, history and result, and the detector that judges the speed history;
// the loop that produces them is the co-simulation's (mobility/cosim_loop.h).
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/mobility/mobility_params.h"

namespace dem_mobility::core {

class ResultFile;
class TerrainModel;

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
