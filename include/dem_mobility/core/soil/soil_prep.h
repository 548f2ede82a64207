// The soil preparation every soil scene shares (paper sections 3 and 4.2): particles poured from a
// loose lattice settle under gravity; a lid consolidates them at a pressure (33.3 kPa) for a time
// (0.5 s) and is removed; the soil settles again. SoilPreparation steps through it; LidHold is the
// lid's control loop, which the compression test also runs at each of its pressures.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {


/// Positions of `count` particles of diameter d on a jittered square lattice (spacing `spacing`
/// d) over the floor z = 0, layer after layer, inside the region where `inside(x, y)` holds
/// (checked for the particle's centre). Deterministic for a seed.
///
/// By default the lattice starts 0.6 d from the low walls, so its rows leave up to a spacing more
/// room at the high side (a few per cent more particles per area on the low side of a small
/// region), and the last, partial layer takes the first sites in row order (y outermost), so it
/// covers one side: a bed thicker there, which a lid then consolidates more than the other side.
/// `spread_last_layer` centres the lattice between the walls and spreads the last layer evenly
/// over the region (every row and column gets its share): a level bed. The cone and single-wheel
/// scenes keep the default, with which their calibration tables and results were made.
std::vector<Eigen::Vector3d> PourLattice(int count, double d, double spacing, const Eigen::Vector2d& lo,
                                         const Eigen::Vector2d& hi,
                                         const std::function<bool(double, double)>& inside, unsigned seed,
                                         bool spread_last_layer = false);

/// A lid driven down onto the particles at a speed proportional to the force it still lacks of
/// `target` (up to `max_speed`), so that it settles on the target without overshoot: its loop gain
/// per step, max_speed dt k_layer / target (k_layer: the stiffness of one layer of contacts under
/// the lid), is capped at 0.5.
class LidPress {
 public:
  LidPress(double target_force, double max_speed, double dt, double k_layer);
  /// Lid speed along z for the force the particles now put on it (fz > 0: pushing it up).
  double Velocity(double fz) const;
  double target() const { return target_; }
  double max_speed() const { return v_max_; }

 private:
  double target_, v_max_;
};

/// Holds a lid (a DEM wall moving along z, pressing down) at a pressure: each step the lid moves at
/// LidPress's speed for the force the particles put on it at the last step, then the DEM steps.
/// The hold counts from the step the force first meets the start criterion; from then on it
/// averages the pressure and the lid's height.
class LidHold {
 public:
  /// When the hold starts: once the force first reaches 95 % of the target, or once it is within
  /// 5 % of it.
  enum class Start { kReaches95Percent, kWithin5Percent };
  LidHold(DemSystem* s, int lid, double area, double pressure, double max_speed, Start start);
  /// The same hold on another system (a copy of this one's).
  void Rebind(DemSystem* s) { s_ = s; }
  void Step();
  bool holding() const { return held_ >= 0.0; }
  double held_time() const { return std::max(0.0, held_); }
  double mean_pressure() const { return sum_pressure_ / std::max(1L, samples_); }  ///< [Pa] over the hold
  double mean_volume() const { return area_ * sum_height_ / std::max(1L, samples_); }  ///< under the lid [m^3]
  const LidPress& press() const { return press_; }
  template <class Ar>
  void Io(Ar& ar) {
    ar(held_, sum_pressure_, sum_height_, samples_);
  }

 private:
  DemSystem* s_;
  int lid_;
  double area_;
  Start start_;
  LidPress press_;
  double held_ = -1.0, sum_pressure_ = 0.0, sum_height_ = 0.0;
  long samples_ = 0;
};

/// How the released bed comes to rest (the release phase, sampled every `interval`): its median
/// particle speed, its kinetic energy, and the energy the soil law's plastic changes put into the
/// particles' contacts (the DEM's plastic ledger, on through the release; > 0: energy the plastic
/// deformations store, which the bed then turns into motion).
struct RestWatch {
  static constexpr double kRestSpeed = 1e-3;  ///< [m/s] a median particle speed below it: at rest
  double interval = 0.01;       ///< [s] between samples
  double median_speed = 0.0;    ///< [m/s] at the last sample
  double kinetic = 0.0;         ///< [J] at the last sample
  double kinetic_max = 0.0;     ///< [J] largest at a sample
  double time_to_rest = -1.0;   ///< [s] since the release, first sample at rest; < 0: never
  double plastic = 0.0;         ///< [J] the plastic exchange over the release
  double plastic_max_power = 0.0;  ///< [W] its largest mean over a sample interval
  double watched = 0.0;         ///< [s] of release sampled
  int samples = 0;
  template <class Ar>
  void Io(Ar& ar) {
    ar(median_speed, kinetic, kinetic_max, time_to_rest, plastic, plastic_max_power, watched, samples);
  }
};

/// The watch's figures in a result file, each name after `prefix` ("settle_"): median_speed, time
/// (since the release, when the median speed first fell below kRestSpeed; -1: not by its end),
/// kinetic, kinetic_max, plastic_work, plastic_max_power, watched (the release's length sampled).
void DescribeRest(const RestWatch& w, const std::string& prefix, ResultFile* r);

/// The median speed of the live particles [m/s] (0 without particles).
double MedianParticleSpeed(const DemSystem& s);

struct SoilPreparationParams {
  double settle_time = 0.5;      ///< [s] after the pour, before the lid
  double lid_pressure = 33.3e3;  ///< [Pa]
  double lid_speed = 0.05;       ///< [m/s] most the lid moves
  double hold_time = 0.5;        ///< [s] at the pressure
  double release_time = 0.2;     ///< [s] of settling after the lid is gone
  double timeout = 30.0;         ///< [s] longest the lid may take to reach its pressure, and to come free
};

/// The preparation of a poured bed under a lid wall: pour (settle), consolidate, retreat (the lid
/// goes up until it is clear of the particles, then is parked), release (settle again).
class SoilPreparation {
 public:
  enum class Phase { kPour, kConsolidate, kRetreat, kRelease, kDone };
  /// `area`: the bed's horizontal area [m^2]; `park_z`: where the lid waits before and after;
  /// `who`: names the scene in error messages.
  SoilPreparation(DemSystem* s, int lid, double area, double park_z, const SoilPreparationParams& p,
                  const std::string& who);
  /// A copy of `o` preparing `s` (a copy of o's system).
  SoilPreparation(const SoilPreparation& o, DemSystem* s);
  /// One DEM step of the current phase (none for a phase of zero duration). SimulationError when
  /// the lid takes longer than `timeout` to reach its pressure, or to come free (the DEM's own
  /// watchdogs throw too).
  void Step();
  bool done() const { return phase_ == Phase::kDone; }
  Phase phase() const { return phase_; }
  static const char* PhaseName(Phase p);
  /// What the current phase waits for, in one line: the pour's and release's settling time, the
  /// lid's height and pressure against its target while it consolidates, its height as it retreats.
  std::string Detail() const;
  double height_poured() const { return height_poured_; }              ///< layer height before the lid [m]
  double height_consolidated() const { return height_consolidated_; }  ///< after the release [m]
  double lid_pressure_reached() const { return hold_ ? hold_->mean_pressure() : 0.0; }  ///< [Pa]
  /// How the bed came to rest after the lid (filled in through the release).
  const RestWatch& rest() const { return rest_; }
  /// Its state in a checkpoint (common/state_archive.h): the phase, its steps, the lid's hold.
  template <class Ar>
  void Io(Ar& ar);

 private:
  void NextPhase(Phase next);
  void WatchRest(bool first);
  DemSystem* s_;
  int lid_;
  double area_, park_z_;
  SoilPreparationParams p_;
  std::string who_;
  Phase phase_ = Phase::kPour;
  long phase_steps_ = 0;
  std::unique_ptr<LidHold> hold_;
  double height_poured_ = 0.0, height_consolidated_ = 0.0;
  RestWatch rest_;
  double rest_plastic0_ = 0.0, rest_plastic_last_ = 0.0;  // the ledger at the release's start, at the last sample
  bool ledger_before_ = false;                           // the DEM's plastic ledger before the release
};

/// Height of a particle layer: the mean top of the highest 5 % of the particles.
double LayerHeight(const DemSystem& s);

/// A cylindrical container (axis z, floor at z = 0) with `count` particles of the system's
/// diameter poured into it from a jittered lattice, and a lid disk just above them.
struct CylinderBed {
  int floor = -1, lid = -1;  ///< wall indices
  double wall_height = 0.0;  ///< of the container's side
};
CylinderBed AddCylinderBed(DemSystem* s, double radius, int count, int segments, unsigned seed);

/// The scene's fidelity level: every entry under `levels:` is read (and so checked) with
/// `read(reader, name)`, the one named by `fidelity:` is returned; ConfigError naming `fidelity`
/// and the known levels otherwise.
template <class Level, class Read>
Level ReadFidelityLevel(const YamlReader& y, Read&& read) {
  const std::string fidelity = y.String("fidelity");
  const YamlReader levels = y.Child("levels");
  std::string names;
  Level chosen;
  bool found = false;
  for (const std::string& name : levels.Keys()) {
    Level l = read(levels.Child(name), name);
    names += (names.empty() ? "" : ", ") + name;
    if (name == fidelity) {
      chosen = std::move(l);
      found = true;
    }
  }
  if (!found) y.Fail("fidelity", "no level '" + fidelity + "' under levels: (" + names + ")");
  return chosen;
}

/// The `threads` key of a scene (OpenMP threads, default 1, in [1, 256]).
int ReadThreads(const YamlReader& y);

/// Checks that `y` is a scene file of `kind` (its `scene:` key) and reads its soil file (`soil:`,
/// relative to the scene file). ConfigError names the file and key.
SoilParams ReadSceneSoil(const YamlReader& y, const std::string& kind);

/// Height of the highest particle centre (0 without particles).
double TopParticle(const DemSystem& s);

}  // namespace dem_mobility::core
