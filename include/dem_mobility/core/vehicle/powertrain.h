// Drive torque limits (WOT and engine-brake curves at the drive shaft, paper fig. 16) and brakes
// (maximum torque versus wheel speed, fig. 17).
#pragma once

#include "dem_mobility/core/common/table.h"

namespace dem_mobility::core {

class YamlReader;

struct PowertrainParams {
  Table1D wot;            ///< drive-shaft speed [rad/s] -> maximum drive torque [N m]
  Table1D engine_brake;   ///< drive-shaft speed [rad/s] -> minimum (most negative) torque [N m]
  Table1D brake_max;      ///< wheel speed [rad/s] -> maximum brake torque per wheel [N m]
  double brake_stiffness = 0.0;   ///< [N m/rad] stick spring of the brake (asperity model)
  double brake_damping = 0.0;     ///< [N m s/rad]

  /// Reads wot_torque, engine_brake_torque and brakes from a powertrain file; checks that the
  /// engine-brake curve lies below the WOT curve at every tabulated speed.
  static PowertrainParams Read(const YamlReader& y);

  /// The drive torque actually applied: the request clamped between the two curves at `w_ds`.
  double ClampDriveTorque(double request, double w_ds) const;
  /// Brake torque on a wheel spinning at `w_rel` relative to its upright: a stick spring from the
  /// wheel's angle to an anchor, in parallel with a damper, capped at effort x max torque (the
  /// anchor slides when the cap is reached). `angle` is the wheel angle relative to the upright,
  /// `anchor` the brake's state. A released brake (effort 0) follows the wheel.
  double BrakeTorque(double effort, double angle, double w_rel, double* anchor) const;
};

}  // namespace dem_mobility::core
