#include "dem_mobility/core/vehicle/vehicle.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

struct Penalty {
  double k = 0.0, c = 0.0;
};
Penalty ReadPenalty(const YamlReader& y) {
  Penalty p{y.Positive("k"), y.NonNegative("c")};
  y.Finish();
  return p;
}

// Mass and inertia of a block like {mass: 5.8, inertia: [Ixx, Iyy, Izz]}, checked.
void ReadMass(const YamlReader& y, double* mass, Matrix3d* inertia) {
  *mass = y.Positive("mass");
  const Vector3d d = y.Vector3("inertia");
  if (d.minCoeff() <= 0.0)
    y.Fail("inertia", detail::Concat("principal moments [", d.transpose(), "] kg m^2 must be positive"));
  if (d(0) + d(1) < d(2) || d(1) + d(2) < d(0) || d(0) + d(2) < d(1))
    y.Fail("inertia", detail::Concat("principal moments [", d.transpose(),
                                     "] kg m^2 violate the triangle inequality (not a physical body)"));
  *inertia = d.asDiagonal();
}

// Uniform rod between p0 and p1: inertia about its centre.
Matrix3d RodInertia(double m, double radius, const Vector3d& p0, const Vector3d& p1) {
  const Vector3d d = p1 - p0;
  const double l = d.norm();
  const Vector3d e = d / l;
  const Matrix3d ee = e * e.transpose();
  return m * (3.0 * radius * radius + l * l) / 12.0 * (Matrix3d::Identity() - ee) + 0.5 * m * radius * radius * ee;
}

class Builder {
 public:
  Builder(MultibodySystem* sys, Vector3d origin, Penalty point, Penalty rot)
      : sys_(sys), origin_(origin), point_(point), rot_(rot) {}

  int Body(const std::string& name, double m, const Matrix3d& inertia, const Vector3d& com_vehicle) {
    RigidBody b;
    b.name = name;
    b.mass = m;
    b.inertia = inertia;
    b.x = origin_ + com_vehicle;
    return sys_->AddBody(b);
  }
  int Rod(const std::string& name, double m, double radius, const Vector3d& p0, const Vector3d& p1) {
    return Body(name, m, RodInertia(m, radius, p0, p1), 0.5 * (p0 + p1));
  }
  Vector3d Local(int body, const Vector3d& p_vehicle) const {
    return p_vehicle + origin_ - sys_->body(body).x;  // bodies are assembled with R = I
  }
  void Spherical(const std::string& name, int a, int b, const Vector3d& p) {
    PointJoint j;
    j.name = name;
    j.a = a;
    j.b = b;
    j.ra = Local(a, p);
    j.rb = Local(b, p);
    j.k = point_.k;
    j.c = point_.c;
    sys_->point_joints.push_back(j);
  }
  // Revolute joint as two spherical points on the axis (paper fig. 4).
  void Revolute(const std::string& name, int a, int b, const Vector3d& p, const Vector3d& axis, double half_span) {
    Spherical(name + "/1", a, b, p + half_span * axis);
    Spherical(name + "/2", a, b, p - half_span * axis);
  }
  void Coupling(const std::string& name, int housing, std::vector<RotationalCoupling::Term> terms) {
    RotationalCoupling c;
    c.name = name;
    c.housing = housing;
    c.terms = std::move(terms);
    c.k = rot_.k;
    c.c = rot_.c;
    sys_->couplings.push_back(c);
  }
  // Constant-velocity joint: spherical at p, twist of b about ub equal to that of a about ua.
  void Cv(const std::string& name, int a, int b, const Vector3d& p, const Vector3d& ua, const Vector3d& ub) {
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
    t.k = rot_.k;
    t.c = rot_.c;
    sys_->cv_twists.push_back(t);
  }
  SpringDamper Spring(const std::string& name, int a, int b, const Vector3d& pa, const Vector3d& pb) const {
    SpringDamper s;
    s.name = name;
    s.a = a;
    s.b = b;
    s.ra = Local(a, pa);
    s.rb = Local(b, pb);
    return s;
  }
  MultibodySystem* sys_;
  Vector3d origin_;
  Penalty point_, rot_;
};

const char* kCorner[4] = {"fl", "fr", "rl", "rr"};

TireGeometry ReadTire(const YamlReader& ty) {
  TireGeometry t = TireGeometry::Make(ty.Positive("radius"), ty.Positive("width"), ty.NonNegative("shoulder_radius"),
                                      ty.Int("n_circ"), ty.Int("n_lat"));
  ty.Finish();
  return t;
}

}  // namespace

TireGeometry LoadTireGeometry(const std::string& file) {
  const YamlReader top = YamlReader::Load(file);
  return ReadTire(YamlReader::Load(top.ResolvePath(top.String("tire"))));
}

std::unique_ptr<Vehicle> Vehicle::Load(const std::string& file, const Vector3d& position) {
  std::unique_ptr<Vehicle> v(new Vehicle());
  MultibodySystem& sys = v->system_;
  const YamlReader top = YamlReader::Load(file);
  v->name_ = top.String("name");
  const double wheelbase = top.Positive("wheelbase");
  const YamlReader pen = top.Child("penalty");
  const Penalty point = ReadPenalty(pen.Child("point"));
  const Penalty rot = ReadPenalty(pen.Child("rotational"));
  pen.Finish();

  const YamlReader sf = YamlReader::Load(top.ResolvePath(top.String("suspension_front")));
  const YamlReader sr = YamlReader::Load(top.ResolvePath(top.String("suspension_rear")));
  const YamlReader st = YamlReader::Load(top.ResolvePath(top.String("steering")));
  const YamlReader dl = YamlReader::Load(top.ResolvePath(top.String("driveline")));
  const YamlReader pt = YamlReader::Load(top.ResolvePath(top.String("powertrain")));
  const YamlReader ty = YamlReader::Load(top.ResolvePath(top.String("tire")));
  v->powertrain_ = PowertrainParams::Read(pt);
  v->tire_ = ReadTire(ty);

  Builder B(&sys, position, point, rot);

  // ---- driveline and steering masses carried by the chassis (part of the sprung mass)
  const double ratio = v->reduction_ = dl.DoubleIn("final_drive_ratio", 1e-3, 10.0);
  const YamlReader ds_y = dl.Child("drive_shaft");
  const double ds_mass = ds_y.Positive("mass"), ds_radius = ds_y.Positive("radius");
  ds_y.Finish();
  const YamlReader pin_y = dl.Child("pinion");
  double pin_mass;
  Matrix3d pin_I;
  ReadMass(pin_y, &pin_mass, &pin_I);
  const double pin_offset = pin_y.Positive("offset");
  pin_y.Finish();
  const YamlReader car_y = dl.Child("carrier");
  double car_mass;
  Matrix3d car_I;
  ReadMass(car_y, &car_mass, &car_I);
  car_y.Finish();
  const YamlReader sg_y = dl.Child("side_gear");
  double sg_mass;
  Matrix3d sg_I;
  ReadMass(sg_y, &sg_mass, &sg_I);
  const double sg_offset = sg_y.Positive("offset");
  sg_y.Finish();
  const YamlReader hs_y = dl.Child("half_shaft");
  const double hs_mass = hs_y.Positive("mass"), hs_radius = hs_y.Positive("radius");
  const double hs_inner = hs_y.Positive("inner_offset"), hs_inset = hs_y.Positive("outer_inset");
  hs_y.Finish();
  dl.Finish();
  const YamlReader rack_y = st.Child("rack");
  const double rack_mass = rack_y.Positive("mass"), rack_radius = rack_y.Positive("radius");
  rack_y.Finish();
  v->max_rack_travel_ = st.Positive("max_rack_travel");
  const Penalty actuator = ReadPenalty(st.Child("actuator"));
  const Penalty spin_lock = ReadPenalty(st.Child("spin_lock"));
  st.Finish();

  // ---- chassis
  const YamlReader ch = top.Child("chassis");
  const double sprung = ch.Positive("sprung_mass");
  const double carried = rack_mass + ds_mass + 2.0 * (pin_mass + car_mass + 2.0 * sg_mass);
  const double chassis_mass = sprung - carried;
  if (chassis_mass <= 0.0)
    ch.Fail("sprung_mass", detail::Concat("sprung mass ", sprung, " kg is less than the ", carried,
                                          " kg of driveline and steering parts it carries"));
  const Vector3d com = ch.Vector3("com");
  const Vector3d ipk = ch.Vector3("inertia_per_kg");
  if (ipk.minCoeff() <= 0.0) ch.Fail("inertia_per_kg", "must be positive");
  ch.Finish();
  v->chassis_com_offset_ = com;
  const int chassis = v->chassis_ = B.Body("chassis", chassis_mass, (chassis_mass * ipk).asDiagonal(), com);

  // ---- suspensions
  int rack = -1;
  int tierod_body[2] = {-1, -1};
  Vector3d rack_end[2];
  double spindle_z = 0.0;
  Vector3d spindle_pos[4];
  const double x_front = sf.Double("x_offset"), x_rear = sr.Double("x_offset");
  if (std::abs((x_front - x_rear) - wheelbase) > 1e-3)
    top.Fail("wheelbase", detail::Concat("wheelbase ", wheelbase, " m differs from the suspensions' x_offset ",
                                         x_front, " - (", x_rear, ") m"));
  for (int axle = 0; axle < 2; ++axle) {
    const YamlReader& S = axle == 0 ? sf : sr;
    const double x_off = axle == 0 ? x_front : x_rear;
    const YamlReader hp = S.Child("hardpoints");
    const char* names[] = {"spindle", "upright", "uca_front", "uca_back", "uca_upright", "lca_front", "lca_back",
                           "lca_upright", "shock_chassis", "shock_arm", "spring_chassis", "spring_arm",
                           "tierod_chassis", "tierod_upright"};
    std::map<std::string, Vector3d> H;
    for (const char* n : names) H[n] = hp.Vector3(n);
    hp.Finish();
    spindle_z = H["spindle"].z();
    const YamlReader ms = S.Child("masses");
    double m_up, m_uca, m_lca, m_wh;
    Matrix3d I_up, I_uca, I_lca, I_wh;
    ReadMass(ms.Child("upright"), &m_up, &I_up);
    ReadMass(ms.Child("uca"), &m_uca, &I_uca);
    ReadMass(ms.Child("lca"), &m_lca, &I_lca);
    ReadMass(ms.Child("wheel"), &m_wh, &I_wh);
    double m_tr = 0.0, r_tr = 0.0;
    if (axle == 0) {
      const YamlReader tr = ms.Child("tierod");
      m_tr = tr.Positive("mass");
      r_tr = tr.Positive("radius");
      tr.Finish();
    }
    ms.Finish();
    Penalty toe{};
    if (axle == 1) toe = ReadPenalty(S.Child("toe_link"));
    const YamlReader sp = S.Child("spring");
    const double free_length = sp.Positive("free_length");
    const Table1D spring_table = sp.Table("force_table");
    const double min_len = sp.Positive("min_length"), max_len = sp.Positive("max_length");
    if (max_len <= min_len) sp.Fail("max_length", "must be larger than min_length");
    const double stop_k = sp.Positive("stop_k"), stop_c = sp.NonNegative("stop_c");
    sp.Finish();
    const YamlReader sh = S.Child("shock");
    const Table1D damper = sh.Table("damper_table");
    sh.Finish();
    S.Finish();

    for (int side = 0; side < 2; ++side) {
      const int corner = axle * 2 + side;
      const double s = side == 0 ? 1.0 : -1.0;
      auto P = [&](const char* n) {
        const Vector3d& h = H[n];
        return Vector3d(h.x() + x_off, s * h.y(), h.z());
      };
      const std::string c = kCorner[corner];
      const int up = B.Body("upright_" + c, m_up, I_up, P("upright"));
      const int uca = B.Body("uca_" + c, m_uca, I_uca, (P("uca_front") + P("uca_back") + P("uca_upright")) / 3.0);
      const int lca = B.Body("lca_" + c, m_lca, I_lca, (P("lca_front") + P("lca_back") + P("lca_upright")) / 3.0);
      const int wh = B.Body("wheel_" + c, m_wh, I_wh, P("spindle"));
      v->wheels_[corner] = wh;
      v->uprights_[corner] = up;
      spindle_pos[corner] = P("spindle");
      B.Spherical("uca_chassis_front_" + c, chassis, uca, P("uca_front"));
      B.Spherical("uca_chassis_back_" + c, chassis, uca, P("uca_back"));
      B.Spherical("lca_chassis_front_" + c, chassis, lca, P("lca_front"));
      B.Spherical("lca_chassis_back_" + c, chassis, lca, P("lca_back"));
      B.Spherical("uca_balljoint_" + c, uca, up, P("uca_upright"));
      B.Spherical("lca_balljoint_" + c, lca, up, P("lca_upright"));
      B.Revolute("spindle_" + c, up, wh, P("spindle"), Vector3d::UnitY(), 0.08);
      SpringDamper spring = B.Spring("spring_" + c, chassis, lca, P("spring_chassis"), P("spring_arm"));
      spring.free_length = free_length;
      spring.spring = spring_table;
      spring.min_length = min_len;
      spring.max_length = max_len;
      spring.stop_k = stop_k;
      spring.stop_c = stop_c;
      sys.springs.push_back(spring);
      SpringDamper shock = B.Spring("shock_" + c, chassis, lca, P("shock_chassis"), P("shock_arm"));
      shock.damper = damper;
      shock.free_length = shock.Length(sys.bodies());
      sys.springs.push_back(shock);
      if (axle == 0) {
        rack_end[side] = P("tierod_chassis");
        tierod_body[side] = B.Rod("tierod_" + std::string(side == 0 ? "left" : "right"), m_tr, r_tr,
                                  P("tierod_chassis"), P("tierod_upright"));
        B.Spherical("tierod_upright_" + c, tierod_body[side], up, P("tierod_upright"));
      } else {
        SpringDamper link = B.Spring("toe_link_" + c, chassis, up, P("tierod_chassis"), P("tierod_upright"));
        link.free_length = link.Length(sys.bodies());
        link.linear_k = toe.k;
        link.linear_c = toe.c;
        sys.springs.push_back(link);
      }
      // brake: torque on the wheel about its spin axis, reacting on the upright
      AxisTorque brake;
      brake.name = "brake_" + c;
      brake.housing = up;
      brake.body = wh;
      brake.axis = Vector3d::UnitY();
      v->brakes_[corner] = static_cast<int>(sys.torques.size());
      sys.torques.push_back(brake);
    }
  }

  // ---- steering: rack sliding along y in the chassis, tie rods to its ends
  rack = B.Rod("rack", rack_mass, rack_radius, rack_end[0], rack_end[1]);
  {
    LineConstraint lc;
    lc.name = "rack_prismatic";
    lc.a = chassis;
    lc.b = rack;
    lc.ra = B.Local(chassis, 0.5 * (rack_end[0] + rack_end[1]));
    lc.u = Vector3d::UnitY();
    lc.rb = Vector3d::Zero();
    lc.k = point.k;
    lc.c = point.c;
    lc.drive = true;
    lc.k_drive = actuator.k;
    lc.c_drive = actuator.c;
    v->steering_ = static_cast<int>(sys.line_constraints.size());
    sys.line_constraints.push_back(lc);
    OrientationLock ol;
    ol.name = "rack_prismatic/orientation";
    ol.a = chassis;
    ol.b = rack;
    ol.k = spin_lock.k;
    ol.c = spin_lock.c;
    sys.orientation_locks.push_back(ol);
    for (int side = 0; side < 2; ++side)
      B.Spherical(std::string("tierod_rack_") + (side == 0 ? "left" : "right"), rack, tierod_body[side], rack_end[side]);
  }

  // ---- axles: pinion -> carrier (final drive), open differential, side gears -> half shafts -> wheels
  int pinion[2];
  for (int axle = 0; axle < 2; ++axle) {
    const std::string an = axle == 0 ? "front" : "rear";
    const double x_axle = 0.5 * (spindle_pos[axle * 2].x() + spindle_pos[axle * 2 + 1].x());
    const double inward = x_axle > 0 ? -1.0 : 1.0;
    const Vector3d c(x_axle, 0.0, spindle_z);
    pinion[axle] = B.Body("pinion_" + an, pin_mass, pin_I, c + Vector3d(inward * pin_offset, 0, 0));
    const int carrier = B.Body("carrier_" + an, car_mass, car_I, c);
    int side_gear[2];
    for (int side = 0; side < 2; ++side) {
      const double s = side == 0 ? 1.0 : -1.0;
      side_gear[side] = B.Body("side_gear_" + an + (side == 0 ? "_left" : "_right"), sg_mass, sg_I,
                               c + Vector3d(0, s * sg_offset, 0));
      B.Revolute("side_gear_bearing_" + an + (side == 0 ? "_left" : "_right"), chassis, side_gear[side],
                 sys.body(side_gear[side]).x - position, Vector3d::UnitY(), 0.03);
    }
    B.Revolute("pinion_bearing_" + an, chassis, pinion[axle], sys.body(pinion[axle]).x - position,
               Vector3d::UnitX(), 0.05);
    B.Revolute("carrier_bearing_" + an, chassis, carrier, c, Vector3d::UnitY(), 0.05);
    B.Coupling("final_drive_" + an, chassis,
               {{carrier, Vector3d::UnitY(), 1.0}, {pinion[axle], Vector3d::UnitX(), -ratio}});
    B.Coupling("differential_" + an, chassis,
               {{side_gear[0], Vector3d::UnitY(), 1.0}, {side_gear[1], Vector3d::UnitY(), 1.0},
                {carrier, Vector3d::UnitY(), -2.0}});
    for (int side = 0; side < 2; ++side) {
      const int corner = axle * 2 + side;
      const double s = side == 0 ? 1.0 : -1.0;
      const Vector3d inner = c + Vector3d(0, s * hs_inner, 0);
      const Vector3d outer = spindle_pos[corner] - Vector3d(0, s * hs_inset, 0);
      if (s * (outer.y() - inner.y()) <= 0.05)
        dl.Fail("half_shaft", "inner_offset and outer_inset leave no length for the half shaft");
      const std::string c_name = kCorner[corner];
      const int hs = B.Rod("half_shaft_" + c_name, hs_mass, hs_radius, inner, outer);
      const Vector3d axis = (s * (outer - inner)).normalized();  // points to +y on both sides
      B.Cv("cv_inner_" + c_name, side_gear[side], hs, inner, Vector3d::UnitY(), axis);
      B.Cv("cv_outer_" + c_name, hs, v->wheels_[corner], outer, axis, Vector3d::UnitY());
    }
  }

  // ---- drive shaft: carrier of the centre differential between the two pinions
  const Vector3d pf = sys.body(pinion[0]).x - position, pr = sys.body(pinion[1]).x - position;
  const int ds = B.Rod("drive_shaft", ds_mass, ds_radius, pf, pr);
  B.Revolute("drive_shaft_bearing", chassis, ds, 0.5 * (pf + pr), Vector3d::UnitX(), 0.4 * (pf - pr).norm());
  B.Coupling("centre_differential", chassis,
             {{pinion[0], Vector3d::UnitX(), 1.0}, {pinion[1], Vector3d::UnitX(), 1.0}, {ds, Vector3d::UnitX(), -2.0}});
  AxisTorque drive;
  drive.name = "drive_torque";
  drive.housing = chassis;
  drive.body = ds;
  drive.axis = Vector3d::UnitX();
  v->drive_ = static_cast<int>(sys.torques.size());
  sys.torques.push_back(drive);

  top.Finish();
  DM_DEMAND(sys.num_bodies() == 34);  // ground + the paper's 33 bodies

  // ---- tires
  v->ride_height_ = v->tire_.radius - spindle_z;
  Vehicle* self = v.get();
  sys.pre_force_hook = [self](MultibodySystem& s) { self->ApplyPowertrain(s); };
  return v;
}

void Vehicle::ApplyPowertrain(MultibodySystem& sys) {
  AxisTorque& d = sys.torques[drive_];
  d.torque = powertrain_.ClampDriveTorque(drive_request_, d.RelativeSpeed(sys.bodies()));
  for (int i = 0; i < 4; ++i) {
    AxisTorque& b = sys.torques[brakes_[i]];
    const double w = b.RelativeSpeed(sys.bodies());
    brake_angle_[i] += w * sys.dt();
    b.torque = powertrain_.BrakeTorque(brake_effort_, brake_angle_[i], w, &brake_anchor_[i]);
  }
}

void Vehicle::SetSteering(double fraction) {
  system_.line_constraints[steering_].target = std::clamp(fraction, -1.0, 1.0) * max_rack_travel_;
}

Vector3d Vehicle::ChassisFramePosition() const {
  const RigidBody& c = system_.body(chassis_);
  return c.x - c.R * chassis_com_offset_;
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
    const double w2 = stiffness * InverseEffectiveMass(b, Vector3d(0, 0, tire_.radius));
    const double zeta = damping * std::sqrt(w2) / (2.0 * stiffness);
    const double dt = CriticalStep(std::sqrt(w2), zeta);
    if (dt < lim.dt_crit) {
      lim.dt_crit = dt;
      lim.element = std::string("wheel-terrain contact 'tire_") + kCorner[i] + "'";
      lim.detail = detail::Concat("terrain contact stiffness ", stiffness, " N/m, damping ", damping, " N s/m on '",
                                  b.name, "' ", b.mass, " kg");
    }
  }
  return lim;
}

}  // namespace dem_mobility
