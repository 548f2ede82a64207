#include "dem_mobility/core/vehicle/driver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

DriverParams DriverParams::Read(const YamlReader& y) {
  DriverParams p;
  p.accel = y.DoubleIn("accel", 1e-3, 20.0);
  p.v_max = y.DoubleIn("v_max", 0.1, 100.0);
  p.kp = y.NonNegative("kp");
  p.ki = y.NonNegative("ki");
  p.full_throttle = y.Bool("full_throttle", false);
  p.control_period = y.DoubleIn("control_period", 1e-7, 0.1, 1e-3);
  if (y.Has("steering")) {
    const YamlReader s = y.Child("steering");
    p.steer = true;
    p.lookahead_time = s.NonNegative("lookahead_time");
    p.lookahead_min = s.DoubleIn("lookahead_min", 0.1, 1000.0);
    p.full_lock = s.DoubleIn("full_lock_deg", 1.0, 60.0) * M_PI / 180.0;
    s.Finish();
  }
  y.Finish();
  return p;
}

SpeedDriver::SpeedDriver(const DriverParams& p, const PowertrainParams& pt, double vehicle_mass,
                         double wheel_radius, double reduction)
    : p_(p), pt_(pt), mass_(vehicle_mass), radius_(wheel_radius), reduction_(reduction) {}

double SpeedDriver::Steering(double y, double heading, double v) const {
  // (off while the vehicle stands or rolls back: pursuit ahead steers the wrong way in reverse)
  if (!p_.steer || p_.wheelbase <= 0.0 || v <= 0.0) return 0.0;
  // pure pursuit: the arc through the vehicle and the point on the line `lookahead` ahead
  const double l = std::max(p_.lookahead_min, p_.lookahead_time * std::abs(v));
  // the point (x + l, 0) of the line seen from the vehicle: its lateral coordinate in the vehicle's
  // frame (to the left +); the arc's curvature 2 lateral / l^2, the bicycle model's wheel angle
  const double lateral = -(y * std::cos(heading) + l * std::sin(heading));
  const double angle = std::atan(2.0 * p_.wheelbase * lateral / (l * l));
  return std::clamp(angle / p_.full_lock, -1.0, 1.0);
}

double SpeedDriver::SpeedCommand(double t) const { return std::min(p_.v_max, p_.accel * std::max(0.0, t)); }

DriverCommand SpeedDriver::Update(double t, double dt, double v, double w_ds) {
  DriverCommand c;
  const double wot = pt_.wot(w_ds), eb = pt_.engine_brake(w_ds);
  if (p_.full_throttle) {
    c.speed_command = std::numeric_limits<double>::infinity();
    c.torque_request = c.drive_torque = wot;
    c.wot_limited = true;
    return c;
  }
  c.speed_command = SpeedCommand(t);
  const double a_cmd = c.speed_command < p_.v_max ? p_.accel : 0.0;
  const double e = c.speed_command - v;
  const double force = mass_ * a_cmd + p_.kp * e + p_.ki * integral_;
  c.torque_request = force * radius_ * reduction_;
  c.drive_torque = std::clamp(c.torque_request, eb, wot);
  c.wot_limited = c.torque_request > wot;
  // brakes take what the engine brake cannot: 4 wheels, referred to the drive shaft
  const double brake_capacity = 4.0 * pt_.brake_max(std::abs(w_ds) * reduction_) * reduction_;
  if (c.torque_request < eb && brake_capacity > 0.0)
    c.brake_effort = std::clamp((eb - c.torque_request) / brake_capacity, 0.0, 1.0);
  // anti-windup: integrate only while the request is achievable, or when the error unwinds it
  const bool saturated_high = c.torque_request > wot && e > 0.0;
  const bool saturated_low = c.brake_effort >= 1.0 && e < 0.0;
  if (!saturated_high && !saturated_low) integral_ += e * dt;
  return c;
}

}  // namespace dem_mobility::core
