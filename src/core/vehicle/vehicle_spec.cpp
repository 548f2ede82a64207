#include "dem_mobility/core/vehicle/vehicle_spec.h"

#include <cmath>
#include <string>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

Penalty ReadPenalty(const YamlReader& y) {
  Penalty p{y.Positive("k"), y.NonNegative("c")};
  y.Finish();
  return p;
}

// Mass and inertia of a block like {mass: 5.8, inertia: [Ixx, Iyy, Izz]}, checked; the caller
// finishes the block (it may hold more keys).
MassProperties ReadMass(const YamlReader& y) {
  MassProperties m;
  m.mass = y.Positive("mass");
  const Vector3d d = y.Vector3("inertia");
  if (d.minCoeff() <= 0.0)
    y.Fail("inertia", detail::Concat("principal moments [", d.transpose(), "] kg m^2 must be positive"));
  if (d(0) + d(1) < d(2) || d(1) + d(2) < d(0) || d(0) + d(2) < d(1))
    y.Fail("inertia", detail::Concat("principal moments [", d.transpose(),
                                     "] kg m^2 violate the triangle inequality (not a physical body)"));
  m.inertia = d.asDiagonal();
  return m;
}

MassProperties ReadMassBlock(const YamlReader& y) {
  const MassProperties m = ReadMass(y);
  y.Finish();
  return m;
}

RodSpec ReadRod(const YamlReader& y) {
  RodSpec r;
  r.mass = y.Positive("mass");
  r.radius = y.Positive("radius");
  y.Finish();
  return r;
}

TireGeometry ReadTire(const YamlReader& tire) { return TireGeometry::Read(tire); }

Differential ReadDifferential(const YamlReader& y, const std::string& key) {
  const std::string mode = y.String(key);
  if (mode == "open") return Differential::kOpen;
  if (mode == "locked") return Differential::kLocked;
  y.Fail(key, "must be open or locked, not '" + mode + "'");
}

DrivelineSpec ReadDriveline(const YamlReader& driveline) {
  DrivelineSpec d;
  d.centre_differential = ReadDifferential(driveline, "centre_differential");
  d.axle_differentials = ReadDifferential(driveline, "axle_differentials");
  d.final_drive_ratio = driveline.DoubleIn("final_drive_ratio", 1e-3, 10.0);
  d.drive_shaft = ReadRod(driveline.Child("drive_shaft"));
  const YamlReader pinion = driveline.Child("pinion");
  d.pinion = ReadMass(pinion);
  d.pinion_offset = pinion.Positive("offset");
  pinion.Finish();
  d.carrier = ReadMassBlock(driveline.Child("carrier"));
  const YamlReader side_gear = driveline.Child("side_gear");
  d.side_gear = ReadMass(side_gear);
  d.side_gear_offset = side_gear.Positive("offset");
  side_gear.Finish();
  const YamlReader half_shaft = driveline.Child("half_shaft");
  d.half_shaft.mass = half_shaft.Positive("mass");
  d.half_shaft.radius = half_shaft.Positive("radius");
  d.half_shaft_inner_offset = half_shaft.Positive("inner_offset");
  d.half_shaft_outer_inset = half_shaft.Positive("outer_inset");
  half_shaft.Finish();
  driveline.Finish();
  return d;
}

SteeringSpec ReadSteering(const YamlReader& steering) {
  SteeringSpec s;
  s.rack = ReadRod(steering.Child("rack"));
  s.max_rack_travel = steering.Positive("max_rack_travel");
  s.actuator = ReadPenalty(steering.Child("actuator"));
  s.spin_lock = ReadPenalty(steering.Child("spin_lock"));
  steering.Finish();
  return s;
}

// The chassis block; `carried` is the mass of the parts the chassis body carries.
ChassisSpec ReadChassis(const YamlReader& chassis, double carried) {
  ChassisSpec c;
  c.sprung_mass = chassis.Positive("sprung_mass");
  if (c.sprung_mass - carried <= 0.0)
    chassis.Fail("sprung_mass", detail::Concat("sprung mass ", c.sprung_mass, " kg is less than the ", carried,
                                               " kg of driveline and steering parts it carries"));
  c.com = chassis.Vector3("com");
  c.inertia_per_kg = chassis.Vector3("inertia_per_kg");
  if (c.inertia_per_kg.minCoeff() <= 0.0) chassis.Fail("inertia_per_kg", "must be positive");
  chassis.Finish();
  return c;
}

SuspensionSpec::Hardpoints ReadHardpoints(const YamlReader& y) {
  SuspensionSpec::Hardpoints h;
  h.spindle = y.Vector3("spindle");
  h.upright = y.Vector3("upright");
  h.uca_front = y.Vector3("uca_front");
  h.uca_back = y.Vector3("uca_back");
  h.uca_upright = y.Vector3("uca_upright");
  h.lca_front = y.Vector3("lca_front");
  h.lca_back = y.Vector3("lca_back");
  h.lca_upright = y.Vector3("lca_upright");
  h.shock_chassis = y.Vector3("shock_chassis");
  h.shock_arm = y.Vector3("shock_arm");
  h.spring_chassis = y.Vector3("spring_chassis");
  h.spring_arm = y.Vector3("spring_arm");
  h.tierod_chassis = y.Vector3("tierod_chassis");
  h.tierod_upright = y.Vector3("tierod_upright");
  y.Finish();
  return h;
}

SuspensionSpec::Spring ReadSpring(const YamlReader& spring) {
  SuspensionSpec::Spring s;
  s.free_length = spring.Positive("free_length");
  s.force_table = spring.Table("force_table");
  s.min_length = spring.Positive("min_length");
  s.max_length = spring.Positive("max_length");
  if (s.max_length <= s.min_length) spring.Fail("max_length", "must be larger than min_length");
  s.stop_k = spring.Positive("stop_k");
  s.stop_c = spring.NonNegative("stop_c");
  spring.Finish();
  return s;
}

// The rest of a suspension file after its x_offset: the front (steered) axle has tie rods, the
// rear a toe link.
void ReadSuspension(const YamlReader& y, bool steered, SuspensionSpec* s) {
  s->hardpoints = ReadHardpoints(y.Child("hardpoints"));
  const YamlReader masses = y.Child("masses");
  s->upright = ReadMass(masses.Child("upright"));
  s->uca = ReadMass(masses.Child("uca"));
  s->lca = ReadMass(masses.Child("lca"));
  s->wheel = ReadMass(masses.Child("wheel"));
  if (steered) s->tierod = ReadRod(masses.Child("tierod"));
  masses.Finish();
  if (!steered) s->toe_link = ReadPenalty(y.Child("toe_link"));
  s->spring = ReadSpring(y.Child("spring"));
  const YamlReader shock = y.Child("shock");
  s->damper_table = shock.Table("damper_table");
  shock.Finish();
  y.Finish();
}

// Each half shaft must keep some length between its inner CV joint (beside the axle centre) and
// its outer one (inboard of the spindle).
void CheckHalfShafts(const VehicleSpec& spec, const YamlReader& driveline) {
  const DrivelineSpec& d = spec.driveline;
  for (int axle = 0; axle < 2; ++axle) {
    const SuspensionSpec& suspension = spec.suspension(axle);
    const double x_axle = 0.5 * (suspension.Corner(suspension.hardpoints.spindle, 0).x() +
                                 suspension.Corner(suspension.hardpoints.spindle, 1).x());
    const Vector3d centre(x_axle, 0.0, spec.AxleHeight());
    for (int side = 0; side < 2; ++side) {
      const double s = side == 0 ? 1.0 : -1.0;
      const Vector3d inner = centre + Vector3d(0, s * d.half_shaft_inner_offset, 0);
      const Vector3d outer = suspension.Corner(suspension.hardpoints.spindle, side) -
                             Vector3d(0, s * d.half_shaft_outer_inset, 0);
      if (s * (outer.y() - inner.y()) <= 0.05)
        driveline.Fail("half_shaft", "inner_offset and outer_inset leave no length for the half shaft");
    }
  }
}

}  // namespace

VehicleSpec VehicleSpec::Load(const std::string& file, const YamlOpener& opener) {
  const YamlOpener open = opener ? opener : YamlOpener(&YamlReader::Load);
  VehicleSpec spec;
  const YamlReader top = open(file);
  spec.name = top.String("name");
  spec.wheelbase = top.Positive("wheelbase");
  const YamlReader penalty = top.Child("penalty");
  spec.point_penalty = ReadPenalty(penalty.Child("point"));
  spec.rotational_penalty = ReadPenalty(penalty.Child("rotational"));
  penalty.Finish();

  const YamlReader suspension_front = open(top.ResolvePath(top.String("suspension_front")));
  const YamlReader suspension_rear = open(top.ResolvePath(top.String("suspension_rear")));
  const YamlReader steering = open(top.ResolvePath(top.String("steering")));
  const YamlReader driveline = open(top.ResolvePath(top.String("driveline")));
  const YamlReader powertrain = open(top.ResolvePath(top.String("powertrain")));
  const YamlReader tire = open(top.ResolvePath(top.String("tire")));
  spec.powertrain = PowertrainParams::Read(powertrain);
  spec.tire = ReadTire(tire);
  spec.driveline = ReadDriveline(driveline);
  spec.steering = ReadSteering(steering);
  spec.chassis = ReadChassis(top.Child("chassis"), spec.CarriedMass());

  spec.suspension_front.x_offset = suspension_front.Double("x_offset");
  spec.suspension_rear.x_offset = suspension_rear.Double("x_offset");
  const double x_front = spec.suspension_front.x_offset, x_rear = spec.suspension_rear.x_offset;
  if (std::abs((x_front - x_rear) - spec.wheelbase) > 1e-3)
    top.Fail("wheelbase", detail::Concat("wheelbase ", spec.wheelbase, " m differs from the suspensions' x_offset ",
                                         x_front, " - (", x_rear, ") m"));
  ReadSuspension(suspension_front, true, &spec.suspension_front);
  ReadSuspension(suspension_rear, false, &spec.suspension_rear);
  CheckHalfShafts(spec, driveline);
  top.Finish();
  return spec;
}

double VehicleSpec::CarriedMass() const {
  const DrivelineSpec& d = driveline;
  return steering.rack.mass + d.drive_shaft.mass + 2.0 * (d.pinion.mass + d.carrier.mass + 2.0 * d.side_gear.mass);
}

double VehicleSpec::TotalMass() const {
  // chassis; per corner upright, upper and lower arm, wheel (and on the steered axle the tie rod);
  // rack; per axle pinion, carrier, two side gears, two half shafts; drive shaft
  double m = 0.0;
  m += ChassisBodyMass();
  for (int axle = 0; axle < 2; ++axle) {
    const SuspensionSpec& s = suspension(axle);
    for (int side = 0; side < 2; ++side) {
      m += s.upright.mass;
      m += s.uca.mass;
      m += s.lca.mass;
      m += s.wheel.mass;
      if (axle == 0) m += s.tierod.mass;
    }
  }
  m += steering.rack.mass;
  for (int axle = 0; axle < 2; ++axle) {
    m += driveline.pinion.mass;
    m += driveline.carrier.mass;
    m += driveline.side_gear.mass;
    m += driveline.side_gear.mass;
    m += driveline.half_shaft.mass;
    m += driveline.half_shaft.mass;
  }
  m += driveline.drive_shaft.mass;
  return m;
}

}  // namespace dem_mobility::core
