// The cone penetrometer of the paper's section 3 (table 1, figs. 11-13): soil poured into a
// cylindrical container and settled, consolidated by a flat lid at 33.3 kPa for 0.5 s, the lid
// removed; then a 30-degree cone (base 0.375 m, length 0.7 m) is driven down at 0.1 m/s by a PID
// controller on its prescribed motion. CI = steady-state penetration force / cone base area, in
// psi. The scene runs step by step (the terrain nodelet shows and records it as it goes) or to the
// end (Run()).
//
// Fidelity levels: the scene file names one of its `levels:` (particle size, container, soil
// depth, penetration speed, time step, CI window): `paper` is table 1 with 3 cm particles; the
// coarser ones are what this machine runs in minutes.
#pragma once

#include <chrono>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/soil/soil_strength.h"

namespace dem_mobility::core {

class YamlReader;

/// One psi in pascals.
constexpr double kPsi = 6894.757293168;

struct ConeLevel {
  std::string name;
  double particle_diameter = 0.03;   ///< [m] (overrides the soil file's)
  double container_diameter = 2.0;   ///< [m]
  double soil_depth = 1.5;           ///< poured depth the particle count is chosen for [m]
  double cone_speed = 0.1;           ///< [m/s] through the CI window
  /// An optional faster approach: the cone descends at approach_speed until its tip is
  /// approach_depth below the surface (above the window), then at cone_speed. 0: no approach.
  double approach_speed = 0.0, approach_depth = 0.0;
  double time_step = 1.5e-5;         ///< [s]
  double settle_time = 0.6;          ///< [s] after the pour
  double hold_time = 0.5;            ///< [s] at the lid pressure
  double ci_from = 0.8, ci_to = 1.0; ///< tip depths below the surface of the CI window [m]; the run ends at ci_to
};

struct ConeParams {
  std::string file;
  SoilParams soil;                 ///< with the level's diameter, f and mu applied
  ConeLevel level;
  double friction = 0.1;           ///< inter-particle mu
  SoilStrength strength;           ///< f, and the table it came from (for the level's particles and mu)
  int container_segments = 24;
  double solid_fraction = 0.58;    ///< poured solid fraction assumed for the particle count
  // the penetrometer (table 1)
  double base_diameter = 0.375, cone_length = 0.7, cone_angle_deg = 30.0;
  double rod_diameter = 0.15;      ///< the shaft above the base
  double cone_mass = 200.0;        ///< cone, shaft and drive [kg]
  double cone_friction = 0.5;      ///< particle-cone mu (table 2)
  double start_gap = 0.02;         ///< tip above the surface at the start of the penetration [m]
  int cone_segments = 24;
  double kp = 0.0, ki = 0.0, kd = 0.0;  ///< PID on the prescribed tip height [N/m, N/(m s), N s/m]
  // the lid
  double lid_pressure = 33.3e3, lid_speed = 0.5, release_time = 0.1;
  double sample_interval = 0.01;   ///< [s] between CI samples
  int threads = 1;
  unsigned seed = 1;
  /// Reads a scene file (`scene: cone_penetrometer`); `fidelity` picks one of its levels. Throws
  /// ConfigError naming the file and key: f outside [0.05, 12], a cone wider than the container, a
  /// cone whose length and angle disagree, a window deeper than the soil, an unknown level.
  static ConeParams Read(const YamlReader& y);
  int ParticleCount() const;
  double BaseArea() const;
};

/// One CI sample: averages over `sample_interval`.
struct ConeSample {
  double t = 0.0;       ///< [s] since the start of the penetration
  double depth = 0.0;   ///< tip depth below the surface [m]
  double speed = 0.0;   ///< downward [m/s]
  double force = 0.0;   ///< the soil's upward force on the penetrometer [N]
  double cone_index_psi = 0.0;  ///< force / base area [psi]
  using StateBulk = void;       ///< (plain doubles: a checkpoint copies it as bytes)
};

struct ConeResult {
  std::string level;
  int particles = 0;
  double cohesion_factor = 0.0, friction = 0.0, requested_cone_index_psi = std::numeric_limits<double>::quiet_NaN();
  double surface_height = 0.0;       ///< soil surface after the preparation [m]
  double density_poured = 0.0, density_consolidated = 0.0;  ///< bulk [kg/m^3]
  double lid_pressure_reached = 0.0; ///< mean over the hold [Pa]
  RestWatch rest;                    ///< how the bed came to rest after the lid
  double cone_index_psi = 0.0;               ///< mean over the window: the cone index
  double cone_index_std_psi = 0.0;           ///< scatter of the samples in the window
  double cone_index_trend_psi_per_m = 0.0;   ///< slope of CI over tip depth in the window
  double speed_min = 0.0, speed_max = 0.0;  ///< of the samples in the soil (tip below one diameter and past the approach)
  int window_samples = 0;
  std::vector<ConeSample> samples;
  double prep_time = 0.0;            ///< simulated time of the preparation [s]
  double sim_time = 0.0, wall_time = 0.0, time_step = 0.0;
  long steps = 0;
  std::string error;                 ///< empty on success
};

class ConePenetrometer final : public SoilRig {
 public:
  /// Builds the container, the tools and the particles (ConfigError on an unusable setup).
  explicit ConePenetrometer(const ConeParams& p);
  ~ConePenetrometer() override;

  // the soil rig
  const char* kind() const override { return "cone_penetrometer"; }
  void Step() override;
  bool done() const override { return phase_ == Phase::kDone; }
  void Fail(const std::string& error) override { error_ = error; }
  const DemSystem& dem() const override { return *dem_; }
  std::string phase() const override;
  std::string StatusLine() const override;
  std::vector<int> moving_walls() const override { return {cone_, rod_, lid_}; }
  ResultFile Report() const override;
  void SaveState(StateWriter& out) const override;
  void LoadState(StateReader& in) override;

  /// Steps to the end; `progress(*this)` is called every `every` steps. Numerical failures end
  /// the run with `error` set and what was measured so far.
  ConeResult Run(const std::function<void(const ConePenetrometer&)>& progress = nullptr, long every = 1000);
  /// What was measured so far (the CI window's statistics once the run is past it).
  ConeResult Result() const;

  bool penetrating() const { return phase_ != Phase::kPrepare; }
  const ConeParams& params() const { return p_; }
  int cone_wall() const { return cone_; }
  int rod_wall() const { return rod_; }
  int lid_wall() const { return lid_; }
  int floor_wall() const { return floor_; }
  double tip_height() const { return z_tip_; }
  double tip_depth() const { return surface_ - z_tip_; }  ///< below the surface (after the preparation)
  double cone_speed() const { return -v_tip_; }           ///< downward
  double penetration_force() const;                       ///< the soil's upward force now [N]
  double surface_height() const { return surface_; }
  const std::vector<ConeSample>& samples() const { return samples_; }

 private:
  enum class Phase { kPrepare, kPenetrate, kDone };
  void PlaceCone();
  /// The prescribed tip height and velocity at time t (the approach, then cone_speed).
  void Reference(double t, double* z, double* v) const;
  void StepCone();
  void StartPenetration();
  void Sample();
  template <class Ar>
  void Io(Ar& ar);
  double WallTime() const;

  ConeParams p_;
  std::unique_ptr<DemSystem> dem_;
  std::unique_ptr<SoilPreparation> prep_;
  int cone_ = -1, rod_ = -1, lid_ = -1, floor_ = -1;
  Phase phase_ = Phase::kPrepare;
  // the cone: tip height and speed, the PID's integral, the prescribed start
  double z_tip_ = 0.0, v_tip_ = 0.0, integral_ = 0.0, z0_ = 0.0, t0_ = 0.0;
  double surface_ = 0.0;
  // the current sample
  double sample_force_ = 0.0, sample_z_ = 0.0, sample_t_ = 0.0;
  long sample_steps_ = 0;
  std::vector<ConeSample> samples_;
  std::chrono::steady_clock::time_point wall0_;
  std::string error_;
};

/// The result file (the one schema: scene, kind, status, error, then the figures and the CI history).
ResultFile ConeResultFile(const ConeResult& r, const ConeParams& p);

}  // namespace dem_mobility::core
