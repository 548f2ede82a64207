#include "dem_mobility/core/vehicle/powertrain.h"

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

PowertrainParams PowertrainParams::Read(const YamlReader& y) {
  PowertrainParams p;
  p.wot = y.Table("wot_torque");
  p.engine_brake = y.Table("engine_brake_torque");
  for (double w : p.wot.x())
    if (p.engine_brake(w) > p.wot(w))
      y.Fail("engine_brake_torque", detail::Concat("engine-brake torque ", p.engine_brake(w), " N m at ", w,
                                                   " rad/s lies above the WOT torque ", p.wot(w), " N m"));
  const YamlReader b = y.Child("brakes");
  p.brake_max = b.Table("max_torque");
  for (double t : p.brake_max.y())
    if (t < 0) b.Fail("max_torque", detail::Concat("brake torque ", t, " N m must not be negative"));
  p.brake_stiffness = b.Positive("stiffness");
  p.brake_damping = b.NonNegative("damping");
  b.Finish();
  y.Finish();
  return p;
}

double PowertrainParams::ClampDriveTorque(double request, double w_ds) const {
  return std::clamp(request, engine_brake(w_ds), wot(w_ds));
}

double PowertrainParams::BrakeTorque(double effort, double angle, double w_rel, double* anchor) const {
  effort = std::clamp(effort, 0.0, 1.0);
  const double limit = effort * brake_max(std::abs(w_rel));
  double t = -brake_stiffness * (angle - *anchor) - brake_damping * w_rel;
  if (std::abs(t) > limit) {
    t = std::copysign(limit, t);
    *anchor = angle + (t + brake_damping * w_rel) / brake_stiffness;  // slide the anchor
    if (limit == 0.0) *anchor = angle;
  }
  return t;
}

}  // namespace dem_mobility::core
