#include "dem_mobility/core/vehicle/vehicle.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

void Vehicle::ApplyPowertrain(MultibodySystem& sys) {
  AxisTorque& d = sys.torques[drive_];
  d.torque = spec_.powertrain.ClampDriveTorque(drive_request_, d.RelativeSpeed(sys.bodies()));
  for (int i = 0; i < 4; ++i) {
    AxisTorque& b = sys.torques[brakes_[i]];
    const double w = b.RelativeSpeed(sys.bodies());
    brake_angle_[i] += w * sys.dt();
    b.torque = spec_.powertrain.BrakeTorque(brake_effort_, brake_angle_[i], w, &brake_anchor_[i]);
  }
}

Vector3d Vehicle::ChassisFramePosition() const {
  const RigidBody& c = system_.body(chassis_);
  return c.x - c.R * chassis_com_offset_;
}
void Vehicle::SetSteering(double fraction) {
  // the rack moving to +y (the vehicle's left) turns the wheels to the right
  if (rack_ >= 0)
    system_.line_constraints[rack_].target = -std::clamp(fraction, -1.0, 1.0) * spec_.steering.max_rack_travel;
}

double Vehicle::Heading() const {
  const Eigen::Vector3d ax = system_.body(chassis_).R.col(0);
  return std::atan2(ax.y(), ax.x());
}

double Vehicle::ForwardSpeed() const {
  const RigidBody& c = system_.body(chassis_);
  return c.v.dot(c.R.col(0));
}
double Vehicle::DriveShaftSpeed() const { return system_.torques[drive_].RelativeSpeed(system_.bodies()); }
double Vehicle::WheelSpeed(int i) const { return system_.torques[brakes_[i]].RelativeSpeed(system_.bodies()); }
double Vehicle::AppliedDriveTorque() const { return system_.torques[drive_].torque; }

WheelState Vehicle::GetWheelState(int i) const {
  const RigidBody& b = system_.body(wheels_[i]);
  WheelState s;
  s.position = b.x;
  s.orientation = Eigen::Quaterniond(b.R);
  s.velocity = b.v;
  s.angular_velocity = b.R * b.w;
  return s;
}

void Vehicle::SetWheelWrench(int i, const WheelWrench& w) {
  wrench_[i] = w;
  RigidBody& b = system_.mutable_body(wheels_[i]);
  b.ext_force = w.force;
  b.ext_torque = w.moment;
}

TimeStepLimit Vehicle::WheelContactLimit(double stiffness, double damping) const {
  TimeStepLimit lim;
  lim.dt_crit = std::numeric_limits<double>::infinity();
  if (stiffness <= 0.0) return lim;
  for (int i = 0; i < 4; ++i) {
    const RigidBody& b = system_.body(wheels_[i]);
    const double w2 = stiffness * InverseEffectiveMass(b, Vector3d(0, 0, spec_.tire.radius));
    const double zeta = damping * std::sqrt(w2) / (2.0 * stiffness);
    const double dt = CriticalStep(std::sqrt(w2), zeta);
    if (dt < lim.dt_crit) {
      lim.dt_crit = dt;
      lim.element = std::string("wheel-terrain contact 'tire_") + kWheelNames[i] + "'";
      lim.detail = detail::Concat("terrain contact stiffness ", stiffness, " N/m, damping ", damping, " N s/m on '",
                                  b.name, "' ", b.mass, " kg");
    }
  }
  return lim;
}

}  // namespace dem_mobility::core
