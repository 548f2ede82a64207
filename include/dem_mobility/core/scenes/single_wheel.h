// The single-wheel test rig (the terramechanics soil-bin experiment): a soil bin poured and
// consolidated as in the paper's section 4.2, a carriage that carries the wheel's vertical load, lets
// it sink freely and moves it forward at a constant speed, and the wheel driven at the angular speed
// of a commanded slip s = 1 - v / (omega r), towed (no torque), or at a given torque. It measures
// the drawbar pull DP (the horizontal force the carriage needs to hold its speed, positive when the
// wheel pulls it), the drive torque T and the sinkage z against slip.
//
// Phases: the bin's preparation (pour, consolidate, retreat, release); `load`: the wheel is set on
// the surface and its load ramped up while it is held at rest; `settle`: it rests under the full
// load; `drive`: the carriage accelerates to its speed (the wheel at the commanded slip all along)
// and runs until its travel reaches the end of the measuring window.
#pragma once

#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/core/soil/dem_soil_bin.h"

namespace dem_mobility::core {

class YamlReader;

struct SingleWheelParams {
  std::string file;
  DemSoilParams bin;
  std::string tire_file;
  TireGeometry tire;
  enum class Drive { kSlip, kTowed, kTorque };
  Drive drive = Drive::kSlip;
  double slip = 0.2;            ///< commanded slip in [-1, 1) (drive: slip)
  double torque = 0.0;          ///< [N m] (drive: torque)
  double load_mass = 1230.0;    ///< [kg] carriage and wheel: the vertical load is its weight
  double speed = 1.0;           ///< carriage speed [m/s]
  double wheel_inertia = 6.0;   ///< about the axle [kg m^2] (towed and torque drives)
  double carriage_damping = 5.0e3;  ///< vertical damper of the carriage [N s/m]
  double load_time = 0.3;       ///< [s] the load ramps up
  double settle_time = 0.6;     ///< [s] at rest under the full load
  double accel_time = 0.2;      ///< [s] the carriage ramps up to its speed
  double start_x = 0.0;         ///< wheel centre at the start, from the bin's start [m]
  double window_from = 1.0, window_to = 2.0;  ///< carriage travel of the measuring window [m]
  double sample_interval = 0.01;///< [s]
  double sunk_sinkage = 0.5;    ///< sinkage / radius at which the wheel counts as sunk
  double gravity = 9.81;
  /// Reads a scene file (`scene: single_wheel`). ConfigError naming the file and key: slip outside
  /// [-1, 1) (s = 1 needs an infinite wheel speed at a moving carriage), a tire wider than the bin,
  /// a window that does not fit in the bin, an unknown drive.
  static SingleWheelParams Read(const YamlReader& y);
  double Weight() const { return load_mass * gravity; }
  static const char* DriveName(Drive d);
  /// What is wrong with a drive's slip and torque, as (key of the `wheel` map, message), or an
  /// empty key: a slip outside [-1, 1] (1 with a slip drive: an infinite wheel speed), a torque
  /// outside +-1e5 N m. Read and a rested rig's other drive both check through it.
  static std::pair<std::string, std::string> DriveProblem(Drive drive, double slip, double torque);
};

/// One sample: means over `sample_interval`.
struct WheelSample {
  double t = 0.0;          ///< since the drive started [s]
  double travel = 0.0;     ///< of the carriage [m]
  double speed = 0.0;      ///< carriage [m/s]
  double omega = 0.0;      ///< wheel [rad/s], forward rolling > 0
  double slip = 0.0;       ///< 1 - v / (omega r)
  double sinkage = 0.0;    ///< lowest tire point below the prepared surface [m]
  double drawbar_pull = 0.0;  ///< [N]
  double torque = 0.0;     ///< drive torque [N m]
  double vertical_force = 0.0;  ///< soil's on the wheel [N]
  int contacts = 0;
  using StateBulk = void;  ///< (plain data: a checkpoint copies it as bytes)
};

class SingleWheelRig final : public SoilRig {
 public:
  explicit SingleWheelRig(const SingleWheelParams& p);
  /// A rig on a copy of a bin already prepared (or part-prepared) with the same soil: several slips
  /// on one preparation. ConfigError when the bin's soil or level differ from p's.
  SingleWheelRig(const SingleWheelParams& p, const DemSoilBin& prepared);
  /// A copy of the rig as it stands (its own bin): for benchmarks and what-ifs from one state.
  SingleWheelRig(const SingleWheelRig& o);
  /// A copy of a rig that has rested under its load and not yet driven (driving(), no drive step
  /// taken), driven as `drive`, `slip` and `torque` say: the load and settle phases do not depend
  /// on the drive, so several drives share one rest, each the run a rig of that drive makes from
  /// the start, bit for bit. ConfigError when `rested` has not rested, has driven already, or the
  /// slip or torque is outside what SingleWheelParams::Read allows.
  SingleWheelRig(const SingleWheelRig& rested, SingleWheelParams::Drive drive, double slip, double torque);
  SingleWheelRig& operator=(const SingleWheelRig&) = delete;
  /// OpenMP threads of the DEM from the next step on (results do not depend on it).
  void set_threads(int threads) { bin_->dem().set_threads(threads); }
  const char* kind() const override { return "single_wheel"; }
  void Step() override;
  bool done() const override { return phase_ == Phase::kDone; }
  void Fail(const std::string& error) override { error_ = error; }
  const DemSystem& dem() const override { return bin_->dem(); }
  std::string phase() const override;
  std::string StatusLine() const override;
  std::vector<int> moving_walls() const override { return {bin_->tire_wall(0), bin_->lid_wall()}; }
  ResultFile Report() const override;
  void SaveState(StateWriter& out) const override;
  void LoadState(StateReader& in) override;

  const SingleWheelParams& params() const { return p_; }
  const DemSoilBin& bin() const { return *bin_; }
  bool driving() const { return phase_ == Phase::kDrive || phase_ == Phase::kDone; }
  bool sunk() const { return sunk_; }
  /// The wheel now: its state and the soil's wrench on it (about its centre).
  const WheelState& wheel() const { return wheel_; }
  WheelWrench wrench() const { return bin_->Wrench(0); }
  double travel() const { return x_ - x0_; }
  double drawbar_pull() const { return dp_; }    ///< now [N]
  double drive_torque() const { return torque_; } ///< now [N m]
  double sinkage() const;
  const std::vector<WheelSample>& samples() const { return samples_; }
  const std::string& error() const { return error_; }
  /// Wall-clock seconds since the rig was built, and of them the preparation's.
  double wall_time() const;
  double preparation_wall_time() const { return prep_wall_time_; }

  /// Means and scatter (std) of the samples in the travel window.
  struct Window {
    int samples = 0;
    double dp = 0.0, dp_std = 0.0, torque = 0.0, torque_std = 0.0, sinkage = 0.0, sinkage_std = 0.0;
    double slip = 0.0, omega = 0.0, vertical_force = 0.0;
  };
  Window Measured() const;
  /// At rest under the full load (the last half of the settle phase): the soil's mean vertical
  /// force on the wheel and the mean sinkage.
  double rest_vertical_force() const { return rest_n_ > 0 ? rest_fz_ / rest_n_ : 0.0; }
  double rest_sinkage() const { return rest_n_ > 0 ? rest_sink_ / rest_n_ : 0.0; }

 private:
  enum class Phase { kPrepare, kLoad, kSettle, kDrive, kDone };
  void Place();
  void StepWheel();
  void Sample();
  template <class Ar>
  void Io(Ar& ar);

  SingleWheelParams p_;
  std::unique_ptr<DemSoilBin> bin_;
  Phase phase_ = Phase::kPrepare;
  WheelState wheel_;
  double x0_ = 0.0, x_ = 0.0, z_ = 0.0, vz_ = 0.0, v_ = 0.0, omega_ = 0.0, theta_ = 0.0;
  double t_phase_ = 0.0, dp_ = 0.0, torque_ = 0.0, accel_ = 0.0;
  bool sunk_ = false;
  // the current sample's sums
  double s_dp_ = 0.0, s_torque_ = 0.0, s_fz_ = 0.0, s_sink_ = 0.0, s_omega_ = 0.0, s_t0_ = 0.0, s_x0_ = 0.0;
  long s_n_ = 0;
  double rest_fz_ = 0.0, rest_sink_ = 0.0;
  long rest_n_ = 0;
  std::vector<WheelSample> samples_;
  std::chrono::steady_clock::time_point wall0_;
  double prep_wall_time_ = 0.0;
  std::string error_;
};

/// The rig's result file (the one schema: scene, kind, status, error, then the figures and the
/// history): status ok, sunk, error or interrupted.
ResultFile SingleWheelResultFile(const SingleWheelRig& rig);

}  // namespace dem_mobility::core
