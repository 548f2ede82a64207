// The driver of the paper's scenario (sections 4.1, 4.3): accelerate at a commanded rate from rest
// toward a top speed, within the engine's torque limits, braking when the request is below what
// the engine brake can give.
#pragma once

#include "dem_mobility/core/vehicle/powertrain.h"

namespace dem_mobility::core {

class YamlReader;

struct DriverParams {
  double accel = 1.0;         ///< commanded acceleration [m/s^2]
  double v_max = 25.0;        ///< commanded top speed [m/s]
  double kp = 0.0;            ///< speed feedback [N per m/s]
  double ki = 0.0;            ///< integral feedback [N per m]
  bool full_throttle = false; ///< ignore the profile: request WOT all the time
  double control_period = 1e-3; ///< [s] the driver acts this often (rounded to whole vehicle steps)
  /// Keeping to the start line (x axis) by pure pursuit of a point `lookahead` ahead on it, with
  /// lookahead = max(lookahead_min, lookahead_time x speed); off (no steering) unless `steering:` is given.
  bool steer = false;
  double lookahead_time = 1.0;  ///< [s]
  double lookahead_min = 5.0;   ///< [m]
  double full_lock = 0.0;       ///< [rad] the wheels' angle at full lock (steering fraction 1)
  double wheelbase = 0.0;       ///< [m] of the bicycle model the pursuit steers (from the vehicle)
  static DriverParams Read(const YamlReader& y);
};

/// Command produced each step.
struct DriverCommand {
  using StateBulk = void;
  double speed_command = 0.0;   ///< [m/s]
  double torque_request = 0.0;  ///< drive-shaft torque asked for [N m] (before the engine clamp)
  double drive_torque = 0.0;    ///< after the clamp between engine-brake and WOT curves [N m]
  double brake_effort = 0.0;    ///< [0, 1]
  double steering = 0.0;        ///< fraction of full lock, positive to the left, [-1, 1]
  bool wot_limited = false;     ///< the request exceeds the WOT curve (full throttle)
};

/// Speed controller: force = m a_cmd + kp e + ki int(e); drive-shaft torque = force r / G, where G
/// is the driveline reduction (wheel speed / drive-shaft speed) and r the wheel radius.
class SpeedDriver {
 public:
  SpeedDriver(const DriverParams& p, const PowertrainParams& pt, double vehicle_mass, double wheel_radius,
              double reduction);
  /// Speed command of the profile at time t (from the driver's start).
  double SpeedCommand(double t) const;
  /// Advances the controller by dt at time t with forward speed v and drive-shaft speed w_ds.
  DriverCommand Update(double t, double dt, double v, double w_ds);
  /// The steering fraction that keeps to the start line, from the lateral offset y [m, + left]
  /// and the heading [rad, + left] at forward speed v (0 when steering is off).
  double Steering(double y, double heading, double v) const;
  /// Its state in a checkpoint (common/state_archive.h): the speed error's integral.
  template <class Ar>
  void Io(Ar& ar) {
    ar(integral_);
  }

 private:
  DriverParams p_;
  const PowertrainParams& pt_;
  double mass_, radius_, reduction_;
  double integral_ = 0.0;
};

}  // namespace dem_mobility::core
