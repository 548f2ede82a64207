#include "dem_mobility/core/vehicle/vehicle.h"
#include "dem_mobility/core/common/state_archive.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <map>
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
  if (rack_ < 0) return;
  LineConstraint& rack = system_.line_constraints[rack_];
  const double target = -std::clamp(fraction, -1.0, 1.0) * spec_.steering.max_rack_travel;
  if (target == rack.target) return;
  // moving the servo's target changes its spring's energy at fixed positions: the servo's work
  const double before = rack.PotentialEnergy(system_.bodies());
  rack.target = target;
  servo_work_ += rack.PotentialEnergy(system_.bodies()) - before;
}

void Vehicle::SetRollingSpeed(double v) {
  MultibodySystem& sys = system_;
  // the spinning bodies (in couplings and CV joints) and each one's spin axis in its frame
  std::map<int, int> unknown;
  std::vector<int> body_of;
  std::vector<Vector3d> axis_of;
  const auto add = [&](int b, const Vector3d& axis) {
    if (b == 0 || unknown.count(b)) return;
    unknown[b] = static_cast<int>(body_of.size());
    body_of.push_back(b);
    axis_of.push_back(axis.normalized());
  };
  for (int i = 0; i < 4; ++i) add(wheels_[i], Vector3d::UnitY());
  for (const RotationalCoupling& c : sys.couplings)
    for (const auto& t : c.terms) add(t.body, t.axis);
  for (const CvTwist& c : sys.cv_twists) {
    add(c.a, c.ua);
    add(c.b, c.ub);
  }
  const int n = static_cast<int>(body_of.size());
  const int rows = 4 + static_cast<int>(sys.couplings.size() + sys.cv_twists.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(rows);
  int r = 0;
  for (int i = 0; i < 4; ++i, ++r) {  // each wheel rolls: spin v / r about its axle (+y)
    A(r, unknown[wheels_[i]]) = 1.0;
    rhs(r) = v / spec_.tire.radius;
  }
  for (const RotationalCoupling& c : sys.couplings) {  // sum coeff x spin about the term's axis = 0
    for (const auto& t : c.terms) A(r, unknown[t.body]) += t.coeff * axis_of[unknown[t.body]].dot(t.axis.normalized());
    ++r;
  }
  for (const CvTwist& c : sys.cv_twists) {  // equal spins of the two shafts about their mean axis
    const RigidBody &a = sys.body(c.a), &b = sys.body(c.b);
    const Vector3d m = (a.R * c.ua + b.R * c.ub).normalized();
    A(r, unknown[c.b]) += (b.R * axis_of[unknown[c.b]]).dot(m);
    A(r, unknown[c.a]) -= (a.R * axis_of[unknown[c.a]]).dot(m);
    ++r;
  }
  const Eigen::VectorXd spin = A.colPivHouseholderQr().solve(rhs);
  DM_DEMAND(spin.allFinite() && (A * spin - rhs).norm() <= 1e-9 * (1.0 + rhs.norm()));
  for (int i = 1; i < sys.num_bodies(); ++i) {
    RigidBody& b = sys.mutable_body(i);
    if (b.fixed) continue;
    b.v = Vector3d(v, 0.0, 0.0);  // (as built: every R = I, the chassis x axis is the world x)
    b.w.setZero();
    b.w_world.setZero();
  }
  for (int k = 0; k < n; ++k) {
    RigidBody& b = sys.mutable_body(body_of[k]);
    b.w = spin(k) * axis_of[k];
    b.w_world = b.R * b.w;
  }
}

EnergyReport Vehicle::Energy() const {
  EnergyReport e = system_.Energy();
  for (int i = 0; i < 4; ++i) {
    const double stretch = brake_angle_[i] - brake_anchor_[i];
    e.elastic += 0.5 * spec_.powertrain.brake_stiffness * stretch * stretch;
  }
  e.wall_work = system_.work().external;
  e.exchanged = system_.work().sources + servo_work_;
  e.dissipated = e.wall_work + e.exchanged - (e.Total() - system_.initial_energy());
  return e;
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

std::vector<MultibodySystem::BodyMode> Vehicle::WheelContactModes(double stiffness, double damping) const {
  std::vector<MultibodySystem::BodyMode> modes;
  if (!(stiffness > 0.0)) return modes;
  for (int i = 0; i < 4; ++i) {
    const RigidBody& b = system_.body(wheels_[i]);
    MultibodySystem::BodyMode m;
    m.body = wheels_[i];
    m.name = std::string("wheel-terrain contact 'tire_") + kWheelNames[i] + "'";
    m.mode.omega = std::sqrt(stiffness * InverseEffectiveMass(b, Vector3d(0, 0, spec_.tire.radius)));
    m.mode.zeta = damping * m.mode.omega / (2.0 * stiffness);
    m.mode.detail = detail::Concat("terrain contact stiffness ", stiffness, " N/m, damping ", damping, " N s/m on '",
                                   b.name, "' ", b.mass, " kg");
    modes.push_back(m);
  }
  return modes;
}

template <class Ar>
void Vehicle::Io(Ar& ar) {
  ar.Tag("vehicle");
  system_.Io(ar);
  ar(brake_angle_, brake_anchor_, drive_request_, brake_effort_, servo_work_, wrench_);
}
template void Vehicle::Io(StateWriter&);
template void Vehicle::Io(StateReader&);

}  // namespace dem_mobility::core
