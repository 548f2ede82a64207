// Penalty joints (paper eq. 6-7) and couplings against analytic results.
#include <gtest/gtest.h>

#include <cmath>

#include "dem_mobility/core/common/rotation.h"
#include "test_util.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;
using test::MakeBody;
using test::MakePoint;

constexpr double kK = 1e6, kG = 9.81;

void Revolute(MultibodySystem& s, int a, int b, const Vector3d& p, const Vector3d& axis, double k, double c) {
  s.point_joints.push_back(MakePoint(s, a, b, p + 0.05 * axis, k, c));
  s.point_joints.push_back(MakePoint(s, a, b, p - 0.05 * axis, k, c));
}

TEST(Joints, PendulumPeriodOnASphericalJoint) {
  const double m = 1.0, L = 1.0, Iyy = 0.01, th0 = 0.05;
  MultibodySystem s;
  const int b = s.AddBody(MakeBody("bob", m, Vector3d(0.01, Iyy, 0.01), Vector3d(L * std::sin(th0), 0, -L * std::cos(th0))));
  s.point_joints.push_back(MakePoint(s, 0, b, Vector3d::Zero(), kK, 0.0));
  s.Finalize(1e-4);
  // compound pendulum: T = 2 pi sqrt(I_pivot / (m g L)), amplitude correction 1 + th0^2/16
  const double T = 2 * M_PI * std::sqrt((Iyy + m * L * L) / (m * kG * L)) * (1 + th0 * th0 / 16);
  std::vector<double> crossings;
  double x_prev = s.body(b).x.x();
  while (s.time() < 3.5 * T) {
    s.Step();
    const double x = s.body(b).x.x();
    if (x_prev > 0 && x <= 0) crossings.push_back(s.time() - s.dt() * x / (x - x_prev));
    x_prev = x;
  }
  ASSERT_GE(crossings.size(), 3u);
  const double measured = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  // the penalty spring lengthens the pendulum by m g / k = 1e-5 m: 5e-6 relative
  EXPECT_NEAR(measured, T, 1e-3 * T);
}

TEST(Joints, SphericalGapIsForceOverStiffness) {
  const double m = 10.0;
  MultibodySystem s;
  const int b = s.AddBody(MakeBody("mass", m, Vector3d(0.1, 0.1, 0.1), Vector3d(0, 0, -0.5)));
  s.point_joints.push_back(MakePoint(s, 0, b, Vector3d::Zero(), kK, 2 * std::sqrt(kK * m)));
  s.Finalize(1e-4);
  for (int i = 0; i < 20000; ++i) s.Step();
  EXPECT_NEAR(s.point_joints[0].Gap(s.bodies()), m * kG / kK, 1e-3 * m * kG / kK);
}

TEST(Joints, RevoluteHoldsAgainstAnOffAxisTorqueAndTurnsFreely) {
  const double m = 10.0, T = 100.0;
  MultibodySystem s;
  const int b = s.AddBody(MakeBody("link", m, Vector3d(0.2, 0.2, 0.2), Vector3d(0, 0, -0.5)));
  Revolute(s, 0, b, Vector3d::Zero(), Vector3d::UnitY(), kK, 2e3);
  s.mutable_body(b).ext_torque = Vector3d(T, 0, 0);  // about x: the joint must carry it
  s.Finalize(1e-4);
  for (int i = 0; i < 20000; ++i) s.Step();
  // static: each point carries m g / 2 along z and T / 0.1 along z as a couple
  const double f1 = std::abs(m * kG / 2 + T / 0.1), f2 = std::abs(m * kG / 2 - T / 0.1);
  EXPECT_NEAR(s.point_joints[0].Gap(s.bodies()) + s.point_joints[1].Gap(s.bodies()), (f1 + f2) / kK, 0.02 * (f1 + f2) / kK);
  // about its own axis it turns freely: a torque about y gives alpha = T / I_pivot initially
  MultibodySystem s2;
  const int b2 = s2.AddBody(MakeBody("link", m, Vector3d(0.2, 0.2, 0.2), Vector3d(0, 0, -0.5)));
  Revolute(s2, 0, b2, Vector3d::Zero(), Vector3d::UnitY(), kK, 2e3);
  s2.set_gravity(Vector3d::Zero());
  s2.mutable_body(b2).ext_torque = Vector3d(0, 10.0, 0);
  s2.Finalize(1e-4);
  for (int i = 0; i < 100; ++i) s2.Step();
  const double alpha = s2.body(b2).w.y() / s2.time();
  EXPECT_NEAR(alpha, 10.0 / (0.2 + m * 0.25), 0.01 * 10.0 / (0.2 + m * 0.25));
}

// A 5 kg yoke on a universal joint to the ground at the origin: spherical point plus cross arms
// ua = x (ground side) and ub = y (yoke) kept perpendicular by a penalty of kr.
int UniversalYoke(MultibodySystem& s, double kr) {
  s.set_gravity(Vector3d::Zero());
  const int b = s.AddBody(MakeBody("yoke", 5.0, Vector3d(0.1, 0.1, 0.1), Vector3d(0.3, 0, 0)));
  s.point_joints.push_back(MakePoint(s, 0, b, Vector3d::Zero(), kK, 1e3));
  PerpendicularAxes u;
  u.name = "universal";
  u.a = 0;
  u.b = b;
  u.ua = Vector3d::UnitX();
  u.ub = Vector3d::UnitY();
  u.k = kr;
  u.c = 20.0;
  s.perpendicular_axes.push_back(u);
  return b;
}

TEST(Joints, UniversalResistsTwistOnly) {
  const double kr = 1e4, T = 50.0;
  MultibodySystem s;
  const int b = UniversalYoke(s, kr);
  // cross arms ua (x, on the ground side) and ub (y, on the yoke): rotation about a x b = z is
  // what a universal joint resists; rotation about either arm is free
  s.mutable_body(b).ext_torque = Vector3d(0, 0, T);
  s.Finalize(1e-4);
  for (int i = 0; i < 30000; ++i) s.Step();
  EXPECT_NEAR(s.perpendicular_axes[0].Violation(s.bodies()), -T / kr, 0.02 * T / kr);
  EXPECT_LT(s.body(b).w.norm(), 1e-3);
  // free about the arm x (through the COM): alpha = T / I_xx
  MultibodySystem s2;
  const int b2 = UniversalYoke(s2, kr);
  s2.mutable_body(b2).ext_torque = Vector3d(1.0, 0, 0);
  s2.Finalize(1e-4);
  for (int i = 0; i < 1000; ++i) s2.Step();
  EXPECT_NEAR(s2.body(b2).w.x() / s2.time(), 1.0 / 0.1, 0.01 * 10.0);
}

TEST(Joints, PrismaticSlidesAlongItsAxisOnly) {
  const double m = 4.0, F = 10.0;
  MultibodySystem s;
  const int b = s.AddBody(MakeBody("slider", m, Vector3d(0.05, 0.05, 0.05), Vector3d(0, 0, 0)));
  LineConstraint lc;
  lc.name = "prismatic";
  lc.a = 0;
  lc.b = b;
  lc.ra = Vector3d::Zero();
  lc.u = Vector3d::UnitX();
  lc.rb = Vector3d::Zero();
  lc.k = kK;
  lc.c = 2 * std::sqrt(kK * m);
  s.line_constraints.push_back(lc);
  OrientationLock ol;
  ol.name = "prismatic/orientation";
  ol.a = 0;
  ol.b = b;
  ol.k = 1e4;
  ol.c = 2 * std::sqrt(1e4 * 0.05);
  s.orientation_locks.push_back(ol);
  s.mutable_body(b).ext_force = Vector3d(F, 0, 0);
  s.mutable_body(b).ext_torque = Vector3d(0, 0, 2.0);
  s.Finalize(1e-4);
  for (int i = 0; i < 20000; ++i) s.Step();
  const double t = s.time();
  EXPECT_NEAR(s.body(b).x.x(), 0.5 * F / m * t * t, 1e-3 * 0.5 * F / m * t * t);  // free along x
  EXPECT_NEAR(s.line_constraints[0].Gap(s.bodies()), m * kG / kK, 0.01 * m * kG / kK);
  EXPECT_NEAR(s.orientation_locks[0].Angle(s.bodies()), 2.0 / 1e4, 0.02 * 2.0 / 1e4);
}

TEST(Joints, BracketOfThreePointsHoldsUnderLoad) {
  const double m = 20.0;
  MultibodySystem s;
  const int b = s.AddBody(MakeBody("bracket", m, Vector3d(0.3, 0.3, 0.3), Vector3d(0, 0, -0.2)));
  // an equilateral triangle of points centred over the COM: each carries a third of the weight
  for (const Vector3d& p : {Vector3d(0.1, 0, 0), Vector3d(-0.05, 0.0866025403784, 0), Vector3d(-0.05, -0.0866025403784, 0)})
    s.point_joints.push_back(MakePoint(s, 0, b, p, kK, 2e3));
  s.mutable_body(b).ext_torque = Vector3d(0, 0, 30.0);
  s.Finalize(1e-4);
  for (int i = 0; i < 20000; ++i) s.Step();
  // displacement of the COM: weight shared by three springs; rotation small
  EXPECT_NEAR(s.body(b).x.z() + 0.2, -m * kG / (3 * kK), 0.05 * m * kG / (3 * kK));
  // torsion about z: three springs at radius 0.1 m give 3 k r^2
  EXPECT_NEAR(LogRotation(s.body(b).R).z(), 30.0 / (3 * kK * 0.01), 0.01 * 30.0 / (3 * kK * 0.01));
  EXPECT_LT(s.body(b).v.norm(), 1e-5);
}

TEST(Joints, GearRatioAndTorque) {
  const double ratio = 0.2, T = 10.0, Ip = 0.02, Ic = 0.15;
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  const int p = s.AddBody(MakeBody("pinion", 4.0, Vector3d(Ip, Ip, Ip), Vector3d(-0.3, 0, 0)));
  const int c = s.AddBody(MakeBody("carrier", 12.0, Vector3d(Ic, Ic, Ic), Vector3d(0, 0, 0)));
  Revolute(s, 0, p, s.body(p).x, Vector3d::UnitX(), 1e7, 1e3);
  Revolute(s, 0, c, s.body(c).x, Vector3d::UnitY(), 1e7, 1e3);
  RotationalCoupling g;
  g.name = "gear";
  g.housing = 0;
  g.terms = {{c, Vector3d::UnitY(), 1.0}, {p, Vector3d::UnitX(), -ratio}};
  g.k = 1e5;
  g.c = 20;
  s.couplings.push_back(g);
  s.mutable_body(p).ext_torque = Vector3d(T, 0, 0);
  s.Finalize(5e-5);
  for (int i = 0; i < 20000; ++i) s.Step();
  const double wp = s.body(p).w.x(), wc = s.body(c).w.y();
  EXPECT_NEAR(wc, ratio * wp, 1e-3 * std::abs(ratio * wp));
  // power balance: T wp = d/dt (Ip wp^2 + Ic wc^2)/2 -> alpha_p = T / (Ip + ratio^2 Ic)
  EXPECT_NEAR(wp / s.time(), T / (Ip + ratio * ratio * Ic), 0.01 * T / (Ip + ratio * ratio * Ic));
}

TEST(Joints, OpenDifferentialKinematicsAndEqualTorqueSplit) {
  const double T = 20.0, IL = 0.01, IR = 0.03, Ic = 0.15;
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  const int c = s.AddBody(MakeBody("carrier", 12.0, Vector3d(Ic, Ic, Ic), Vector3d(0, 0, 0)));
  const int l = s.AddBody(MakeBody("left", 3.0, Vector3d(IL, IL, IL), Vector3d(0, 0.12, 0)));
  const int r = s.AddBody(MakeBody("right", 3.0, Vector3d(IR, IR, IR), Vector3d(0, -0.12, 0)));
  for (int b : {c, l, r}) Revolute(s, 0, b, s.body(b).x, Vector3d::UnitY(), 1e7, 1e3);
  RotationalCoupling d;
  d.name = "differential";
  d.housing = 0;
  d.terms = {{l, Vector3d::UnitY(), 1.0}, {r, Vector3d::UnitY(), 1.0}, {c, Vector3d::UnitY(), -2.0}};
  d.k = 1e5;
  d.c = 20;
  s.couplings.push_back(d);
  s.mutable_body(c).ext_torque = Vector3d(0, T, 0);
  s.Finalize(5e-5);
  for (int i = 0; i < 20000; ++i) s.Step();
  const double wl = s.body(l).w.y(), wr = s.body(r).w.y(), wc = s.body(c).w.y();
  EXPECT_NEAR(wc, 0.5 * (wl + wr), 1e-3 * std::abs(wc));
  // equal torque split: I_L alpha_L = I_R alpha_R, and the sides share T less the carrier's part
  const double tl = IL * wl / s.time(), tr = IR * wr / s.time();
  EXPECT_NEAR(tl, tr, 0.01 * tl);
  EXPECT_NEAR(tl + tr + Ic * wc / s.time(), T, 0.01 * T);
}

TEST(Joints, CvJointTransmitsConstantVelocityAtABend) {
  const double bend = 25.0 * M_PI / 180.0, w0 = 10.0;
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  const Vector3d axis_b(std::cos(bend), std::sin(bend), 0.0);
  const int a = s.AddBody(MakeBody("shaft_a", 3.0, Vector3d(0.005, 0.05, 0.05), Vector3d(-0.3, 0, 0)));
  RigidBody bb = MakeBody("shaft_b", 3.0, Vector3d(0.005, 0.05, 0.05), 0.3 * axis_b);
  bb.R = RotZ(bend);  // its body x axis along axis_b
  const int b = s.AddBody(bb);
  Revolute(s, 0, a, s.body(a).x, Vector3d::UnitX(), 1e7, 1e3);
  Revolute(s, 0, b, s.body(b).x, axis_b, 1e7, 1e3);
  s.point_joints.push_back(MakePoint(s, a, b, Vector3d::Zero(), 1e7, 1e3));
  CvTwist cv;
  cv.name = "cv";
  cv.a = a;
  cv.b = b;
  cv.ua = Vector3d::UnitX();
  cv.ub = Vector3d::UnitX();  // in b's own frame
  cv.pa = Vector3d::UnitZ();
  cv.pb = Vector3d::UnitZ();
  cv.k = 1e4;
  cv.c = 5;
  s.cv_twists.push_back(cv);
  s.mutable_body(a).w = Vector3d(w0, 0, 0);
  s.mutable_body(b).w = Vector3d(w0, 0, 0);
  s.Finalize(2e-5);
  // a Cardan joint would make the output speed swing between w cos(b) and w / cos(b) (+-10 %)
  double worst = 0;
  while (s.time() < 2 * M_PI / w0) {
    s.Step();
    const double wa = s.body(a).w.x(), wb = s.body(b).w.x();
    worst = std::max(worst, std::abs(wb - wa) / w0);
  }
  EXPECT_LT(worst, 0.005);
  EXPECT_LT(std::abs(s.cv_twists[0].Twist(s.bodies())), 1e-3);
}

}  // namespace
}  // namespace dem_mobility::core
