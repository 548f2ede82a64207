// The explicit integrator (velocity Verlet realisation of the paper's eq. 3-5) against analytic
// results: torque-free rigid body invariants, second-order convergence, stability limit 2/omega.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dem_mobility/core/common/rotation.h"
#include "test_util.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

// Spins an asymmetric body (I = 1, 2, 3) about an axis near the unstable middle axis for T seconds
// and returns the worst relative drift of energy and |angular momentum|.
std::pair<double, double> TorqueFreeDrift(double dt, double T) {
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  RigidBody b = test::MakeBody("body", 2.0, Vector3d(1.0, 2.0, 3.0));
  b.w = Vector3d(0.3, 2.0, 0.4);
  const int i = s.AddBody(b);
  s.Finalize(dt);
  const double e0 = s.body(i).KineticEnergy();
  const Vector3d l0 = s.body(i).AngularMomentumWorld();
  double de = 0, dl = 0;
  const long n = std::lround(T / dt);
  for (long k = 0; k < n; ++k) {
    s.Step();
    de = std::max(de, std::abs(s.body(i).KineticEnergy() - e0) / e0);
    dl = std::max(dl, (s.body(i).AngularMomentumWorld() - l0).norm() / l0.norm());
  }
  return {de, dl};
}

TEST(Integrator, TorqueFreeBodyConservesEnergyAndMomentum) {
  // tumbling about the intermediate axis: a demanding case (Dzhanibekov flips)
  const auto [de, dl] = TorqueFreeDrift(1e-3, 20.0);
  EXPECT_LT(de, 2e-4);
  EXPECT_LT(dl, 2e-4);
}

TEST(Integrator, TorqueFreeErrorShrinksLikeDtSquared) {
  const double e1 = TorqueFreeDrift(4e-3, 5.0).first;
  const double e2 = TorqueFreeDrift(2e-3, 5.0).first;
  const double e3 = TorqueFreeDrift(1e-3, 5.0).first;
  // halving dt divides a second-order error by 4 (3 to 5.5 allows for the oscillating error's phase)
  EXPECT_GT(e1 / e2, 3.0);
  EXPECT_LT(e1 / e2, 5.5);
  EXPECT_GT(e2 / e3, 3.0);
  EXPECT_LT(e2 / e3, 5.5);
}

TEST(Integrator, RotationStaysOrthonormal) {
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  RigidBody b = test::MakeBody("body", 1.0, Vector3d(1.0, 1.5, 2.0));
  b.w = Vector3d(5.0, -3.0, 7.0);
  const int i = s.AddBody(b);
  s.Finalize(1e-3);
  for (int k = 0; k < 100000; ++k) s.Step();
  const Eigen::Matrix3d& R = s.body(i).R;
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

// Mass m on a penalty point joint to ground (spring k, no damping): the explicit step is stable
// for dt < 2/omega, omega = sqrt(k/m), and the guard must find exactly that limit.
struct Oscillator {
  MultibodySystem s;
  int body;
  Oscillator(double m, double k) {
    s.set_gravity(Vector3d::Zero());
    body = s.AddBody(test::MakeBody("mass", m, Vector3d(1.0, 1.0, 1.0)));
    s.point_joints.push_back(test::MakePoint(s, 0, body, Vector3d::Zero(), k, 0.0));
    s.mutable_body(body).v = Vector3d(1.0, 0.0, 0.0);
  }
};

TEST(Integrator, GuardFindsTheAnalyticCriticalStep) {
  Oscillator o(2.0, 800.0);  // omega = 20 rad/s
  EXPECT_NEAR(o.s.CriticalTimeStep().dt_crit, 2.0 / 20.0, 1e-12);
}

// Largest displacement over 5000 steps at dt = f * 2/omega (guard bypassed for f > 1).
double OscillatorAmplitude(double f) {
  const double m = 2.0, k = 800.0, omega = std::sqrt(k / m);
  Oscillator o(m, k);
  o.s.Finalize(f * 2.0 / omega, /*check_step=*/false);
  double amax = 0;
  try {
    for (int n = 0; n < 5000; ++n) {
      o.s.Step();
      amax = std::max(amax, o.s.body(o.body).x.norm());
    }
  } catch (const SimulationError&) {
    return std::numeric_limits<double>::infinity();
  }
  return amax * omega;  // in units of the exact amplitude v0/omega
}

TEST(Integrator, StableBelowAndUnstableAboveTwoOverOmega) {
  // below the limit the amplitude stays bounded (Verlet inflates it by 1/sqrt(1-(h w/2)^2) = 5 at 0.98)
  EXPECT_LT(OscillatorAmplitude(0.5), 1.2);
  EXPECT_LT(OscillatorAmplitude(0.98), 6.0);
  // above it the amplitude grows without bound
  EXPECT_GT(OscillatorAmplitude(1.02), 1e6);
}

// A light mass held by two springs to the ground: each spring's own mode is omega^2 = k/m, the
// pair's 2k/m. The guard sums the modes on the body (a bound on the assembled system's highest
// frequency): its critical step is the pair's, 2/sqrt(2k/m), exact here; the stiffest element alone
// would allow sqrt(2) times that, where the run diverges.
double TwoSpringAmplitude(double step, double c = 0.0) {
  MultibodySystem s;
  s.set_gravity(Vector3d::Zero());
  const int b = s.AddBody(test::MakeBody("mass", 2.0, Vector3d(1.0, 1.0, 1.0)));
  s.point_joints.push_back(test::MakePoint(s, 0, b, Vector3d::Zero(), 800.0, c));
  s.point_joints.push_back(test::MakePoint(s, 0, b, Vector3d::Zero(), 800.0, c));
  s.mutable_body(b).v = Vector3d(1.0, 0.0, 0.0);
  s.Finalize(step, /*check_step=*/false);
  double amax = 0.0;
  try {
    for (int n = 0; n < 5000; ++n) {
      s.Step();
      amax = std::max(amax, s.body(b).x.norm());
    }
  } catch (const SimulationError&) {
    return std::numeric_limits<double>::infinity();
  }
  return amax * std::sqrt(1600.0 / 2.0);
}

TEST(Integrator, GuardSumsTheElementsOnABody) {
  MultibodySystem s;
  const int b = s.AddBody(test::MakeBody("mass", 2.0, Vector3d(1.0, 1.0, 1.0)));
  s.point_joints.push_back(test::MakePoint(s, 0, b, Vector3d::Zero(), 800.0, 0.0));
  s.point_joints.push_back(test::MakePoint(s, 0, b, Vector3d::Zero(), 800.0, 0.0));
  const double pair = 2.0 / std::sqrt(2.0 * 800.0 / 2.0), single = 2.0 / std::sqrt(800.0 / 2.0);
  EXPECT_NEAR(s.CriticalTimeStep().dt_crit, pair, 1e-12);
  EXPECT_EQ(s.CriticalTimeStep().element, "body 'mass'");
  EXPECT_LT(TwoSpringAmplitude(0.98 * pair), 6.0);
  EXPECT_GT(TwoSpringAmplitude(1.02 * pair), 1e6);
  EXPECT_GT(TwoSpringAmplitude(0.9 * single), 1e6);  // what the stiffest element alone would allow
  // damped (each spring zeta 0.5 on its own mode): the dampers add up as the springs do, the pair's
  // damping ratio is 2 x 0.5 x 20 / sqrt(800) = 0.707 and its step (2/omega)(sqrt(1+zeta^2)-zeta)
  MultibodySystem d;
  const int m = d.AddBody(test::MakeBody("mass", 2.0, Vector3d(1.0, 1.0, 1.0)));
  d.point_joints.push_back(test::MakePoint(d, 0, m, Vector3d::Zero(), 800.0, 40.0));
  d.point_joints.push_back(test::MakePoint(d, 0, m, Vector3d::Zero(), 800.0, 40.0));
  const double omega = std::sqrt(1600.0 / 2.0), zeta = 2.0 * 0.5 * 20.0 / omega;
  const double damped = 2.0 / omega * (std::sqrt(1.0 + zeta * zeta) - zeta);
  EXPECT_NEAR(d.CriticalTimeStep().dt_crit, damped, 1e-12);
  EXPECT_LT(TwoSpringAmplitude(0.98 * damped, 40.0), 6.0);
  EXPECT_GT(TwoSpringAmplitude(1.05 * damped, 40.0), 1e6);
}

TEST(Integrator, GuardRefusesAStepAboveTheLimit) {
  Oscillator o(2.0, 800.0);
  try {
    o.s.Finalize(0.11);
    FAIL() << "a step above 2/omega = 0.1 s was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("critical step"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'point'"), std::string::npos) << e.what();
  }
}

TEST(Integrator, FreeFallIsExact) {
  // constant acceleration: velocity Verlet is exact for a quadratic trajectory
  MultibodySystem s;
  const int i = s.AddBody(test::MakeBody("ball", 1.0, Vector3d(0.1, 0.1, 0.1)));
  s.Finalize(1e-3);
  for (int n = 0; n < 1000; ++n) s.Step();
  EXPECT_NEAR(s.body(i).x.z(), -0.5 * 9.81 * 1.0, 1e-9);
  EXPECT_NEAR(s.body(i).v.z(), -9.81, 1e-9);
}

}  // namespace
}  // namespace dem_mobility::core
