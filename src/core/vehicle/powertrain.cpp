#include "dem_mobility/core/vehicle/powertrain.h"

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility {

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
  p.brake_speed_eps = b.Positive("speed_eps", 0.05);
  b.Finish();
  y.Finish();
  return p;
}

double PowertrainParams::ClampDriveTorque(double request, double w_ds) const {
  return std::clamp(request, engine_brake(w_ds), wot(w_ds));
}

double PowertrainParams::BrakeTorque(double effort, double w_rel) const {
  effort = std::clamp(effort, 0.0, 1.0);
  if (effort == 0.0) return 0.0;
  return -effort * brake_max(std::abs(w_rel)) * std::clamp(w_rel / brake_speed_eps, -1.0, 1.0);
}

}  // namespace dem_mobility
