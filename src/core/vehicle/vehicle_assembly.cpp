// Vehicle::Build: the bodies and elements of the 33-body vehicle, part by part, from a VehicleSpec.
#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/vehicle/vehicle.h"

namespace dem_mobility::core {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

const char* kSide[2] = {"left", "right"};
const char* kAxle[2] = {"front", "rear"};

// Uniform rod between p0 and p1: inertia about its centre.
Matrix3d RodInertia(double m, double radius, const Vector3d& p0, const Vector3d& p1) {
  const Vector3d d = p1 - p0;
  const double l = d.norm();
  const Vector3d e = d / l;
  const Matrix3d ee = e * e.transpose();
  return m * (3.0 * radius * radius + l * l) / 12.0 * (Matrix3d::Identity() - ee) + 0.5 * m * radius * radius * ee;
}

}  // namespace

/// Adds the vehicle's bodies and elements to its MultibodySystem. Points are given in the chassis
/// reference frame (vehicle coordinates); bodies are placed at `origin` + their vehicle-frame COM
/// with R = I. The parts must be added in the order Vehicle::Build calls them: later parts join
/// bodies of earlier ones.
class VehicleAssembler {
 public:
  VehicleAssembler(Vehicle* vehicle, const Vector3d& origin)
      : vehicle_(vehicle),
        spec_(vehicle->spec_),
        system_(vehicle->system_),
        origin_(origin),
        point_(spec_.point_penalty),
        rotational_(spec_.rotational_penalty) {}

  void Chassis();
  /// The suspension of one corner: arms, upright, wheel, spring, shock, brake, and the tie rod
  /// (steered axle) or toe link.
  void Corner(int axle, int side);
  /// The rack between the front tie rods' inner ends, sliding along y in the chassis.
  void Steering();
  /// Pinion, carrier (final drive), differential (open or locked), side gears, half shafts with
  /// CV joints.
  void Axle(int axle);
  /// The drive shaft between the pinions, driving both (centre locked) or the carrier of an open
  /// centre differential between them, and the drive torque.
  void DriveShaft();

 private:
  int Body(const std::string& name, const MassProperties& m, const Vector3d& com_vehicle);
  int Rod(const std::string& name, const RodSpec& rod, const Vector3d& p0, const Vector3d& p1);
  Vector3d Local(int body, const Vector3d& p_vehicle) const;
  void Spherical(const std::string& name, int a, int b, const Vector3d& p);
  void Revolute(const std::string& name, int a, int b, const Vector3d& p, const Vector3d& axis, double half_span);
  void Coupling(const std::string& name, int housing, std::vector<RotationalCoupling::Term> terms);
  void ConstantVelocity(const std::string& name, int a, int b, const Vector3d& p, const Vector3d& ua,
                        const Vector3d& ub);
  SpringDamper Spring(const std::string& name, int a, int b, const Vector3d& pa, const Vector3d& pb) const;

  Vehicle* vehicle_;
  const VehicleSpec& spec_;
  MultibodySystem& system_;
  Vector3d origin_;
  Penalty point_, rotational_;
  // bodies and points of earlier parts that later parts join
  int tierod_[2] = {-1, -1};
  Vector3d rack_end_[2];
  Vector3d spindle_[4];
  int pinion_[2] = {-1, -1};
};

// ---- element helpers

int VehicleAssembler::Body(const std::string& name, const MassProperties& m, const Vector3d& com_vehicle) {
  RigidBody b;
  b.name = name;
  b.mass = m.mass;
  b.inertia = m.inertia;
  b.x = origin_ + com_vehicle;
  return system_.AddBody(b);
}

int VehicleAssembler::Rod(const std::string& name, const RodSpec& rod, const Vector3d& p0, const Vector3d& p1) {
  return Body(name, {rod.mass, RodInertia(rod.mass, rod.radius, p0, p1)}, 0.5 * (p0 + p1));
}

Vector3d VehicleAssembler::Local(int body, const Vector3d& p_vehicle) const {
  return p_vehicle + origin_ - system_.body(body).x;  // bodies are assembled with R = I
}

void VehicleAssembler::Spherical(const std::string& name, int a, int b, const Vector3d& p) {
  PointJoint j;
  j.name = name;
  j.a = a;
  j.b = b;
  j.ra = Local(a, p);
  j.rb = Local(b, p);
  j.k = point_.k;
  j.c = point_.c;
  system_.point_joints.push_back(j);
}

// Revolute joint as two spherical points on the axis (paper fig. 4).
void VehicleAssembler::Revolute(const std::string& name, int a, int b, const Vector3d& p, const Vector3d& axis,
                                double half_span) {
  Spherical(name + "/1", a, b, p + half_span * axis);
  Spherical(name + "/2", a, b, p - half_span * axis);
}

void VehicleAssembler::Coupling(const std::string& name, int housing, std::vector<RotationalCoupling::Term> terms) {
  RotationalCoupling c;
  c.name = name;
  c.housing = housing;
  c.terms = std::move(terms);
  c.k = rotational_.k;
  c.c = rotational_.c;
  system_.couplings.push_back(c);
}

// Constant-velocity joint: spherical at p, twist of b about ub equal to that of a about ua.
void VehicleAssembler::ConstantVelocity(const std::string& name, int a, int b, const Vector3d& p,
                                        const Vector3d& ua, const Vector3d& ub) {
  Spherical(name, a, b, p);
  CvTwist t;
  t.name = name + "/twist";
  t.a = a;
  t.b = b;
  t.ua = ua.normalized();
  t.ub = ub.normalized();
  // a reference perpendicular of a, carried onto b by the minimal rotation (zero twist now)
  Vector3d pa = t.ua.cross(Vector3d::UnitZ());
  if (pa.norm() < 1e-6) pa = t.ua.cross(Vector3d::UnitX());
  pa.normalize();
  const Vector3d v = t.ua.cross(t.ub);
  const double c = t.ua.dot(t.ub);
  t.pa = pa;
  t.pb = (pa * c + v.cross(pa) + v * (v.dot(pa) / (1.0 + c))).normalized();
  t.k = rotational_.k;
  t.c = rotational_.c;
  system_.cv_twists.push_back(t);
}

SpringDamper VehicleAssembler::Spring(const std::string& name, int a, int b, const Vector3d& pa,
                                      const Vector3d& pb) const {
  SpringDamper s;
  s.name = name;
  s.a = a;
  s.b = b;
  s.ra = Local(a, pa);
  s.rb = Local(b, pb);
  return s;
}

// ---- parts

void VehicleAssembler::Chassis() {
  vehicle_->chassis_com_offset_ = spec_.chassis.com;
  const double mass = spec_.ChassisBodyMass();
  vehicle_->chassis_ = Body("chassis", {mass, (mass * spec_.chassis.inertia_per_kg).asDiagonal()}, spec_.chassis.com);
}

void VehicleAssembler::Corner(int axle, int side) {
  const SuspensionSpec& suspension = spec_.suspension(axle);
  const SuspensionSpec::Hardpoints& h = suspension.hardpoints;
  auto point = [&](const Vector3d& left) { return suspension.Corner(left, side); };
  const int corner = axle * 2 + side;
  const std::string c = kWheelNames[corner];
  const int chassis = vehicle_->chassis_;

  const int upright = Body("upright_" + c, suspension.upright, point(h.upright));
  // the arms' centres of mass: the centroids of their three hardpoints
  const int uca =
      Body("uca_" + c, suspension.uca, (point(h.uca_front) + point(h.uca_back) + point(h.uca_upright)) / 3.0);
  const int lca =
      Body("lca_" + c, suspension.lca, (point(h.lca_front) + point(h.lca_back) + point(h.lca_upright)) / 3.0);
  const int wheel = Body("wheel_" + c, suspension.wheel, point(h.spindle));
  vehicle_->wheels_[corner] = wheel;
  spindle_[corner] = point(h.spindle);
  Spherical("uca_chassis_front_" + c, chassis, uca, point(h.uca_front));
  Spherical("uca_chassis_back_" + c, chassis, uca, point(h.uca_back));
  Spherical("lca_chassis_front_" + c, chassis, lca, point(h.lca_front));
  Spherical("lca_chassis_back_" + c, chassis, lca, point(h.lca_back));
  Spherical("uca_balljoint_" + c, uca, upright, point(h.uca_upright));
  Spherical("lca_balljoint_" + c, lca, upright, point(h.lca_upright));
  Revolute("spindle_" + c, upright, wheel, point(h.spindle), Vector3d::UnitY(), 0.08);

  SpringDamper spring = Spring("spring_" + c, chassis, lca, point(h.spring_chassis), point(h.spring_arm));
  spring.free_length = suspension.spring.free_length;
  spring.spring = suspension.spring.force_table;
  spring.min_length = suspension.spring.min_length;
  spring.max_length = suspension.spring.max_length;
  spring.stop_k = suspension.spring.stop_k;
  spring.stop_c = suspension.spring.stop_c;
  system_.springs.push_back(spring);
  SpringDamper shock = Spring("shock_" + c, chassis, lca, point(h.shock_chassis), point(h.shock_arm));
  shock.damper = suspension.damper_table;
  shock.free_length = shock.Length(system_.bodies());
  system_.springs.push_back(shock);

  if (axle == 0) {  // steered: a tie rod from the rack end to the upright
    rack_end_[side] = point(h.tierod_chassis);
    tierod_[side] = Rod(std::string("tierod_") + kSide[side], suspension.tierod, point(h.tierod_chassis),
                        point(h.tierod_upright));
    Spherical("tierod_upright_" + c, tierod_[side], upright, point(h.tierod_upright));
  } else {  // a stiff massless toe link from the chassis to the upright
    SpringDamper link = Spring("toe_link_" + c, chassis, upright, point(h.tierod_chassis), point(h.tierod_upright));
    link.free_length = link.Length(system_.bodies());
    link.linear_k = suspension.toe_link.k;
    link.linear_c = suspension.toe_link.c;
    system_.springs.push_back(link);
  }

  // brake: torque on the wheel about its spin axis, reacting on the upright
  AxisTorque brake;
  brake.name = "brake_" + c;
  brake.housing = upright;
  brake.body = wheel;
  brake.axis = Vector3d::UnitY();
  vehicle_->brakes_[corner] = static_cast<int>(system_.torques.size());
  system_.torques.push_back(brake);
}

void VehicleAssembler::Steering() {
  const int chassis = vehicle_->chassis_;
  const int rack = Rod("rack", spec_.steering.rack, rack_end_[0], rack_end_[1]);
  LineConstraint line;
  line.name = "rack_prismatic";
  line.a = chassis;
  line.b = rack;
  line.ra = Local(chassis, 0.5 * (rack_end_[0] + rack_end_[1]));
  line.u = Vector3d::UnitY();
  line.rb = Vector3d::Zero();
  line.k = point_.k;
  line.c = point_.c;
  line.drive = true;
  line.k_drive = spec_.steering.actuator.k;
  line.c_drive = spec_.steering.actuator.c;
  vehicle_->rack_ = static_cast<int>(system_.line_constraints.size());
  system_.line_constraints.push_back(line);
  OrientationLock lock;
  lock.name = "rack_prismatic/orientation";
  lock.a = chassis;
  lock.b = rack;
  lock.k = spec_.steering.spin_lock.k;
  lock.c = spec_.steering.spin_lock.c;
  system_.orientation_locks.push_back(lock);
  for (int side = 0; side < 2; ++side)
    Spherical(std::string("tierod_rack_") + kSide[side], rack, tierod_[side], rack_end_[side]);
}

void VehicleAssembler::Axle(int axle) {
  const DrivelineSpec& driveline = spec_.driveline;
  const int chassis = vehicle_->chassis_;
  const std::string axle_name = kAxle[axle];
  const double x_axle = 0.5 * (spindle_[axle * 2].x() + spindle_[axle * 2 + 1].x());
  const double inward = x_axle > 0 ? -1.0 : 1.0;
  const Vector3d centre(x_axle, 0.0, spec_.AxleHeight());
  const int pinion = pinion_[axle] =
      Body("pinion_" + axle_name, driveline.pinion, centre + Vector3d(inward * driveline.pinion_offset, 0, 0));
  const int carrier = Body("carrier_" + axle_name, driveline.carrier, centre);
  int side_gear[2];
  for (int side = 0; side < 2; ++side) {
    const double s = side == 0 ? 1.0 : -1.0;
    const std::string name = axle_name + "_" + kSide[side];
    side_gear[side] =
        Body("side_gear_" + name, driveline.side_gear, centre + Vector3d(0, s * driveline.side_gear_offset, 0));
    Revolute("side_gear_bearing_" + name, chassis, side_gear[side], system_.body(side_gear[side]).x - origin_,
             Vector3d::UnitY(), 0.03);
  }
  Revolute("pinion_bearing_" + axle_name, chassis, pinion, system_.body(pinion).x - origin_, Vector3d::UnitX(), 0.05);
  Revolute("carrier_bearing_" + axle_name, chassis, carrier, centre, Vector3d::UnitY(), 0.05);
  Coupling("final_drive_" + axle_name, chassis,
           {{carrier, Vector3d::UnitY(), 1.0}, {pinion, Vector3d::UnitX(), -driveline.final_drive_ratio}});
  if (driveline.axle_differentials == Differential::kOpen) {
    Coupling("differential_" + axle_name, chassis,
             {{side_gear[0], Vector3d::UnitY(), 1.0}, {side_gear[1], Vector3d::UnitY(), 1.0},
              {carrier, Vector3d::UnitY(), -2.0}});
  } else {  // locked: each side gear turns with the carrier
    for (int side = 0; side < 2; ++side)
      Coupling("differential_lock_" + axle_name + "_" + kSide[side], chassis,
               {{side_gear[side], Vector3d::UnitY(), 1.0}, {carrier, Vector3d::UnitY(), -1.0}});
  }
  for (int side = 0; side < 2; ++side) {
    const int corner = axle * 2 + side;
    const double s = side == 0 ? 1.0 : -1.0;
    const Vector3d inner = centre + Vector3d(0, s * driveline.half_shaft_inner_offset, 0);
    const Vector3d outer = spindle_[corner] - Vector3d(0, s * driveline.half_shaft_outer_inset, 0);
    const std::string c = kWheelNames[corner];
    const int half_shaft = Rod("half_shaft_" + c, driveline.half_shaft, inner, outer);
    const Vector3d axis = (s * (outer - inner)).normalized();  // points to +y on both sides
    ConstantVelocity("cv_inner_" + c, side_gear[side], half_shaft, inner, Vector3d::UnitY(), axis);
    ConstantVelocity("cv_outer_" + c, half_shaft, vehicle_->wheels_[corner], outer, axis, Vector3d::UnitY());
  }
}

void VehicleAssembler::DriveShaft() {
  const int chassis = vehicle_->chassis_;
  const Vector3d front = system_.body(pinion_[0]).x - origin_, rear = system_.body(pinion_[1]).x - origin_;
  const int shaft = Rod("drive_shaft", spec_.driveline.drive_shaft, front, rear);
  Revolute("drive_shaft_bearing", chassis, shaft, 0.5 * (front + rear), Vector3d::UnitX(), 0.4 * (front - rear).norm());
  if (spec_.driveline.centre_differential == Differential::kOpen) {
    Coupling("centre_differential", chassis,
             {{pinion_[0], Vector3d::UnitX(), 1.0},
              {pinion_[1], Vector3d::UnitX(), 1.0},
              {shaft, Vector3d::UnitX(), -2.0}});
  } else {  // locked (the paper's): the shaft drives each pinion directly
    for (int axle = 0; axle < 2; ++axle)
      Coupling(std::string("drive_shaft_") + kAxle[axle] + "_pinion", chassis,
               {{pinion_[axle], Vector3d::UnitX(), 1.0}, {shaft, Vector3d::UnitX(), -1.0}});
  }
  AxisTorque drive;
  drive.name = "drive_torque";
  drive.housing = chassis;
  drive.body = shaft;
  drive.axis = Vector3d::UnitX();
  drive.source = true;  // the engine
  vehicle_->drive_ = static_cast<int>(system_.torques.size());
  system_.torques.push_back(drive);
}

std::unique_ptr<Vehicle> Vehicle::Build(const VehicleSpec& spec, const Vector3d& position) {
  std::unique_ptr<Vehicle> v(new Vehicle());
  v->spec_ = spec;
  VehicleAssembler assembler(v.get(), position);
  assembler.Chassis();
  for (int axle = 0; axle < 2; ++axle)
    for (int side = 0; side < 2; ++side) assembler.Corner(axle, side);
  assembler.Steering();
  for (int axle = 0; axle < 2; ++axle) assembler.Axle(axle);
  assembler.DriveShaft();
  DM_DEMAND(v->system_.num_bodies() == 34);  // ground + the paper's 33 bodies

  v->ride_height_ = spec.tire.radius - spec.AxleHeight();
  Vehicle* self = v.get();
  v->system_.pre_force_hook = [self](MultibodySystem& s) { self->ApplyPowertrain(s); };
  return v;
}

}  // namespace dem_mobility::core
