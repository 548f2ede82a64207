#include "dem_mobility/core/multibody/elements.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

using Eigen::Matrix3d;
using Eigen::Vector3d;

double InverseEffectiveMass(const RigidBody& b, const Vector3d& r) {
  if (b.fixed) return 0.0;
  // largest eigenvalue of the point's inverse mass matrix I/m + S(r)^T I_w^-1 S(r)
  Matrix3d s;
  s << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  const Matrix3d m = b.inv_mass * Matrix3d::Identity() + s.transpose() * (b.R * b.inv_inertia * b.R.transpose()) * s;
  Eigen::SelfAdjointEigenSolver<Matrix3d> es;
  es.computeDirect(m, Eigen::EigenvaluesOnly);
  return es.eigenvalues().maxCoeff();
}

double InverseInertiaAbout(const RigidBody& b, const Vector3d& a_world) {
  if (b.fixed) return 0.0;
  const Vector3d a = b.R.transpose() * a_world;
  return a.dot(b.inv_inertia * a);
}

namespace {
// Frequency and damping ratio of a penalty spring k, damper c on a mode with inverse mass inv_m.
StiffnessInfo Mode(double k, double c, double inv_m, const std::string& detail,
                   std::vector<std::pair<int, double>> sides = {}) {
  StiffnessInfo s;
  if (inv_m <= 0.0 || k <= 0.0) return s;
  s.omega = std::sqrt(k * inv_m);
  s.zeta = c * s.omega / (2.0 * k);
  s.detail = detail;
  s.sides = std::move(sides);
  return s;
}
std::string Lightest(const Bodies& bodies, int a, int b) {
  const RigidBody& A = bodies[a];
  const RigidBody& B = bodies[b];
  const RigidBody& l = A.fixed ? B : (B.fixed ? A : (A.mass < B.mass ? A : B));
  return detail::Concat("lightest body '", l.name, "' ", l.mass, " kg");
}
}  // namespace

// ---------------------------------------------------------------------------------------------
void PointJoint::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const Vector3d ra_w = A.R * ra;
  const Vector3d rb_w = B.R * rb;
  const Vector3d d = (B.x + rb_w) - (A.x + ra_w);
  const Vector3d dd = B.VelocityAt(rb_w) - A.VelocityAt(ra_w);
  const Vector3d f = -(k * d + c * dd);  // on B
  B.AddForceAt(f, rb_w);
  A.AddForceAt(-f, ra_w);
}
double PointJoint::Gap(const Bodies& bodies) const {
  return (bodies[b].PointWorld(rb) - bodies[a].PointWorld(ra)).norm();
}
double PointJoint::PotentialEnergy(const Bodies& bodies) const {
  const double g = Gap(bodies);
  return 0.5 * k * g * g;
}
StiffnessInfo PointJoint::Stiffness(const Bodies& bodies) const {
  const double wa = InverseEffectiveMass(bodies[a], bodies[a].R * ra), wb = InverseEffectiveMass(bodies[b], bodies[b].R * rb);
  return Mode(k, c, wa + wb, detail::Concat("k = ", k, " N/m, c = ", c, " N s/m, ", Lightest(bodies, a, b)),
              {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
void PerpendicularAxes::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const Vector3d ua_w = A.R * ua;
  const Vector3d ub_w = B.R * ub;
  const Vector3d ba = ub_w.cross(ua_w);
  const double g = ua_w.dot(ub_w);
  const double g_dot = (B.w_world - A.w_world).dot(ba);
  const Vector3d t = -(k * g + c * g_dot) * ba;  // on B
  B.torque += t;
  A.torque -= t;
}
double PerpendicularAxes::Violation(const Bodies& bodies) const {
  return (bodies[a].R * ua).dot(bodies[b].R * ub);
}
double PerpendicularAxes::PotentialEnergy(const Bodies& bodies) const {
  const double g = Violation(bodies);
  return 0.5 * k * g * g;
}
StiffnessInfo PerpendicularAxes::Stiffness(const Bodies& bodies) const {
  Vector3d axis = (bodies[b].R * ub).cross(bodies[a].R * ua);
  if (axis.norm() < 1e-9) axis = bodies[a].R * ua;
  axis.normalize();
  const double wa = InverseInertiaAbout(bodies[a], axis), wb = InverseInertiaAbout(bodies[b], axis);
  return Mode(k, c, wa + wb, detail::Concat("k = ", k, " N m/rad, ", Lightest(bodies, a, b)), {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
namespace {
// Small-angle rotation vector (world) of R_b relative to its locked orientation R_a R0.
Vector3d LockError(const RigidBody& A, const RigidBody& B, const Matrix3d& R0) {
  const Matrix3d e = B.R * R0.transpose() * A.R.transpose();
  return 0.5 * Vector3d(e(2, 1) - e(1, 2), e(0, 2) - e(2, 0), e(1, 0) - e(0, 1));
}
double MinInverseInertia(const RigidBody& b) { return b.fixed ? 0.0 : 1.0 / b.min_inertia; }
}  // namespace

void OrientationLock::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const Vector3d t = -(k * LockError(A, B, R0) + c * (B.w_world - A.w_world));
  B.torque += t;
  A.torque -= t;
}
double OrientationLock::Angle(const Bodies& bodies) const {
  return LockError(bodies[a], bodies[b], R0).norm();
}
double OrientationLock::PotentialEnergy(const Bodies& bodies) const {
  const double th = Angle(bodies);
  return 0.5 * k * th * th;
}
StiffnessInfo OrientationLock::Stiffness(const Bodies& bodies) const {
  const double wa = MinInverseInertia(bodies[a]), wb = MinInverseInertia(bodies[b]);
  return Mode(k, c, wa + wb, detail::Concat("k = ", k, " N m/rad, ", Lightest(bodies, a, b)), {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
void LineConstraint::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const Vector3d u_w = A.R * u;
  const Vector3d pa = A.PointWorld(ra);
  const Vector3d rb_w = B.R * rb;
  const Vector3d pb = B.x + rb_w;
  const Vector3d ra_w = pb - A.x;  // the material point of A under pb
  const Vector3d e = pb - pa;
  const double s = e.dot(u_w);
  const Vector3d ve = B.VelocityAt(rb_w) - A.VelocityAt(ra_w);
  const double vs = ve.dot(u_w);
  Vector3d f = -(k * (e - s * u_w) + c * (ve - vs * u_w));
  if (drive) f -= (k_drive * (s - target) + c_drive * vs) * u_w;
  B.AddForceAt(f, rb_w);
  A.AddForceAt(-f, ra_w);
}
double LineConstraint::Gap(const Bodies& bodies) const {
  const Vector3d u_w = bodies[a].R * u;
  const Vector3d e = bodies[b].PointWorld(rb) - bodies[a].PointWorld(ra);
  return (e - e.dot(u_w) * u_w).norm();
}
double LineConstraint::Position(const Bodies& bodies) const {
  return (bodies[b].PointWorld(rb) - bodies[a].PointWorld(ra)).dot(bodies[a].R * u);
}
double LineConstraint::PotentialEnergy(const Bodies& bodies) const {
  const double g = Gap(bodies);
  double e = 0.5 * k * g * g;
  if (drive) {
    const double ds = Position(bodies) - target;
    e += 0.5 * k_drive * ds * ds;
  }
  return e;
}
StiffnessInfo LineConstraint::Stiffness(const Bodies& bodies) const {
  const Vector3d pb = bodies[b].PointWorld(rb);
  const double wa = InverseEffectiveMass(bodies[a], pb - bodies[a].x), wb = InverseEffectiveMass(bodies[b], pb - bodies[b].x);
  const double kk = std::max(k, drive ? k_drive : 0.0);
  const double cc = kk == k ? c : c_drive;
  return Mode(kk, cc, wa + wb, detail::Concat("k = ", kk, " N/m, ", Lightest(bodies, a, b)), {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
double RotationalCoupling::Rate(const Bodies& bodies) const {
  const Vector3d& wh = bodies[housing].w_world;
  double r = 0.0;
  for (const Term& t : terms) {
    const RigidBody& B = bodies[t.body];
    r += t.coeff * (B.w_world - wh).dot(B.R * t.axis);
  }
  return r;
}
void RotationalCoupling::Apply(Bodies& bodies) const {
  const double lambda = -(k * g + c * Rate(bodies));
  Vector3d sum = Vector3d::Zero();
  for (const Term& t : terms) {
    RigidBody& B = bodies[t.body];
    const Vector3d tau = (lambda * t.coeff) * (B.R * t.axis);
    B.torque += tau;
    sum += tau;
  }
  bodies[housing].torque -= sum;
}
StiffnessInfo RotationalCoupling::Stiffness(const Bodies& bodies) const {
  double inv_i = 0.0;
  Vector3d sum = Vector3d::Zero();
  std::string lightest;
  double min_i = std::numeric_limits<double>::infinity();
  std::vector<std::pair<int, double>> sides;
  for (const Term& t : terms) {
    const RigidBody& B = bodies[t.body];
    const Vector3d a = B.R * t.axis;
    const double ii = InverseInertiaAbout(B, a);
    inv_i += t.coeff * t.coeff * ii;
    sides.emplace_back(t.body, t.coeff * t.coeff * ii);
    sum += t.coeff * a;
    if (ii > 0 && 1.0 / ii < min_i) {
      min_i = 1.0 / ii;
      lightest = B.name;
    }
  }
  const double sn = sum.norm();
  if (sn > 1e-12) {
    const double wh = sn * sn * InverseInertiaAbout(bodies[housing], sum / sn);
    inv_i += wh;
    sides.emplace_back(housing, wh);
  }
  return Mode(k, c, inv_i, detail::Concat("k = ", k, " N m/rad, smallest inertia '", lightest, "' ", min_i, " kg m^2"),
              std::move(sides));
}

// ---------------------------------------------------------------------------------------------
namespace {
struct CvFrame {
  Vector3d a, b, m;  // axes and bisector
  double phi;
};
CvFrame CvGeometry(const RigidBody& A, const RigidBody& B, const Vector3d& ua, const Vector3d& pa,
                   const Vector3d& ub, const Vector3d& pb) {
  CvFrame f;
  f.a = A.R * ua;
  f.b = B.R * ub;
  const Vector3d p = A.R * pa;
  const Vector3d q = B.R * pb;
  // rotate q by the minimal rotation that takes b onto a
  const Vector3d v = f.b.cross(f.a);
  const double cth = f.b.dot(f.a);
  const Vector3d q2 = q * cth + v.cross(q) + v * (v.dot(q) / (1.0 + cth));
  f.phi = std::atan2(f.a.dot(p.cross(q2)), p.dot(q2));
  f.m = (f.a + f.b).normalized();
  return f;
}
}  // namespace

void CvTwist::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const CvFrame f = CvGeometry(A, B, ua, pa, ub, pb);
  const double phi_dot = (B.w_world - A.w_world).dot(f.m);
  const Vector3d t = -(k * f.phi + c * phi_dot) * f.m;  // on B
  B.torque += t;
  A.torque -= t;
}
double CvTwist::Twist(const Bodies& bodies) const {
  return CvGeometry(bodies[a], bodies[b], ua, pa, ub, pb).phi;
}
double CvTwist::PotentialEnergy(const Bodies& bodies) const {
  const double p = Twist(bodies);
  return 0.5 * k * p * p;
}
StiffnessInfo CvTwist::Stiffness(const Bodies& bodies) const {
  const Vector3d m = (bodies[a].R * ua + bodies[b].R * ub).normalized();
  const double wa = InverseInertiaAbout(bodies[a], m), wb = InverseInertiaAbout(bodies[b], m);
  return Mode(k, c, wa + wb, detail::Concat("k = ", k, " N m/rad, ", Lightest(bodies, a, b)), {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
double SpringDamper::Length(const Bodies& bodies) const {
  return (bodies[b].PointWorld(rb) - bodies[a].PointWorld(ra)).norm();
}
void SpringDamper::Apply(Bodies& bodies) const {
  RigidBody& A = bodies[a];
  RigidBody& B = bodies[b];
  const Vector3d ra_w = A.R * ra;
  const Vector3d rb_w = B.R * rb;
  const Vector3d d = (B.x + rb_w) - (A.x + ra_w);
  const double len = d.norm();
  if (len < 1e-12) return;
  const Vector3d e = d / len;
  const double len_dot = e.dot(B.VelocityAt(rb_w) - A.VelocityAt(ra_w));
  const double x = free_length - len;  // compression
  double f = linear_k * x;             // positive pushes the ends apart
  if (!spring.empty()) f += spring(x);
  if (!damper.empty()) f += damper(-len_dot);
  f -= linear_c * len_dot;
  if (max_length > 0.0) {
    if (len < min_length) f += stop_k * (min_length - len) - stop_c * std::min(len_dot, 0.0);
    if (len > max_length) f -= stop_k * (len - max_length) + stop_c * std::max(len_dot, 0.0);
  }
  const Vector3d fb = f * e;
  B.AddForceAt(fb, rb_w);
  A.AddForceAt(-fb, ra_w);
}
double SpringDamper::PotentialEnergy(const Bodies& bodies) const {
  const double len = Length(bodies);
  const double x = free_length - len;
  double e = 0.5 * linear_k * x * x;
  if (!spring.empty()) e += spring.Integral(0.0, x);
  if (max_length > 0.0) {
    if (len < min_length) e += 0.5 * stop_k * (min_length - len) * (min_length - len);
    if (len > max_length) e += 0.5 * stop_k * (len - max_length) * (len - max_length);
  }
  return e;
}
StiffnessInfo SpringDamper::Stiffness(const Bodies& bodies) const {
  const double wa = InverseEffectiveMass(bodies[a], bodies[a].R * ra), wb = InverseEffectiveMass(bodies[b], bodies[b].R * rb);
  double k = linear_k + (spring.empty() ? 0.0 : spring.MaxSlope());
  double c = linear_c + (damper.empty() ? 0.0 : damper.MaxSlope());
  if (max_length > 0.0) {
    k += stop_k;
    c += stop_c;
  }
  return Mode(k, c, wa + wb, detail::Concat("k = ", k, " N/m, ", Lightest(bodies, a, b)), {{a, wa}, {b, wb}});
}

// ---------------------------------------------------------------------------------------------
double AxisTorque::RelativeSpeed(const Bodies& bodies) const {
  const RigidBody& B = bodies[body];
  return (B.w_world - bodies[housing].w_world).dot(B.R * axis);
}
void AxisTorque::Apply(Bodies& bodies) const {
  RigidBody& B = bodies[body];
  const Vector3d t = torque * (B.R * axis);
  B.torque += t;
  bodies[housing].torque -= t;
}

}  // namespace dem_mobility::core
