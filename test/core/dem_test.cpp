// The DEM solver: collisions against the analytic spring-dashpot, momentum, determinism across
// thread counts, the time-step guard and the watchdogs.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/wall_contacts.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

// two particles meeting head-on at +-v0; returns the speed after they part
double Collide(const SoilParams& p, double v0, double dt_fraction) {
  DemSystem s(p, DemSettings());
  s.set_gravity(Vector3d::Zero());
  const double D = p.diameter;
  s.AddParticle(Vector3d(-0.5 * D - 1e-4, 0, 0), Vector3d(v0, 0, 0));
  s.AddParticle(Vector3d(0.5 * D + 1e-4, 0, 0), Vector3d(-v0, 0, 0));
  const double m_eff = 0.5 * p.Mass(), k = p.NormalStiffness();
  s.Finalize(dt_fraction * 2.0 * std::sqrt(m_eff / k));
  for (int i = 0; i < 200000 && !(s.position(1).x() - s.position(0).x() > D + 2e-4); ++i) s.Step();
  return s.velocity(1).x();
}

TEST(Dem, UndampedHeadOnCollisionConservesEnergy) {
  const double v0 = 0.5;
  const double v1 = Collide(Elastic(0.0), v0, 0.02);
  EXPECT_NEAR(v1, v0, 1e-3 * v0);  // rebounds with the speed it came in with
}

TEST(Dem, DampedHeadOnCollisionMatchesTheAnalyticRestitution) {
  const SoilParams p = Elastic(2.1e4);  // table 2 damping
  const double m_eff = 0.5 * p.Mass(), k = p.NormalStiffness(), c = p.NormalDamping();
  const double zeta = c / (2.0 * std::sqrt(k * m_eff));
  const double e = std::exp(-M_PI * zeta / std::sqrt(1.0 - zeta * zeta));
  const double v0 = 0.5;
  EXPECT_NEAR(Collide(p, v0, 0.02) / v0, e, 0.01 * e);
}

TEST(Dem, AHeldParticleIsAFixedSupportUntilReleased) {
  // a particle striking a held one rebounds as from an immovable body: the restitution of the
  // spring-dashpot with the striker's own mass (not the pair's reduced mass)
  const SoilParams p = Elastic(2.1e4);
  const double m = p.Mass(), k = p.NormalStiffness(), c = p.NormalDamping(), D = p.diameter;
  const double zeta = c / (2.0 * std::sqrt(k * m));
  const double e = std::exp(-M_PI * zeta / std::sqrt(1.0 - zeta * zeta));
  DemSystem s(p, DemSettings());
  s.set_gravity(Vector3d::Zero());
  const double v0 = 0.5;
  const Vector3d x0(0.0, 0.0, 0.0);
  s.AddParticle(x0, Vector3d(0.3, 0.1, 0.0));
  s.AddParticle(Vector3d(D + 1e-4, 0, 0), Vector3d(-v0, 0, 0));
  s.set_held(0, true);
  EXPECT_TRUE(s.held(0));
  EXPECT_EQ(s.velocity(0), Vector3d::Zero());  // its velocity is taken away
  s.Finalize(0.02 * 2.0 * std::sqrt(0.5 * m / k));
  bool touched = false;
  for (int i = 0; i < 200000 && !(touched && s.position(1).x() > D + 2e-4); ++i) {
    s.Step();
    touched = touched || s.contacts() > 0;
    ASSERT_EQ(s.position(0), x0);
    ASSERT_EQ(s.velocity(0), Vector3d::Zero());
  }
  ASSERT_TRUE(touched);
  EXPECT_NEAR(s.velocity(1).x() / v0, e, 0.01 * e);
  // released, it is a particle again: struck once more, it takes momentum (the pair keeps it)
  s.set_held(0, false);
  EXPECT_FALSE(s.held(0));
  s.mutable_velocity(1) = Vector3d(-v0, 0, 0);
  s.mutable_position(1) = Vector3d(D + 1e-4, 0, 0);
  for (int i = 0; i < 200000 && !(s.position(1).x() - s.position(0).x() > D + 2e-4); ++i) s.Step();
  EXPECT_LT(s.velocity(0).x(), -0.5 * v0);  // it moved off
  EXPECT_NEAR(s.Momentum().x(), -m * v0, 1e-9 * m * v0);
}

std::vector<Vector3d> Cluster(int n, unsigned seed, double spacing) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.04, 0.04);
  const int side = static_cast<int>(std::ceil(std::cbrt(n)));
  std::vector<Vector3d> x;
  for (int i = 0; i < n; ++i)
    x.emplace_back(spacing * (i % side + u(rng)), spacing * ((i / side) % side + u(rng)),
                   spacing * (i / (side * side) + u(rng)));
  return x;
}

// particles thrown together (no gravity, no walls): cohesion, plasticity and friction all on
DemSystem Implosion(int n, int threads) {
  DemSettings st;
  st.threads = threads;
  st.max_overlap = 0.2;
  const SoilParams p = Nominal();
  DemSystem s(p, st);
  s.set_gravity(Vector3d::Zero());
  const std::vector<Vector3d> x = Cluster(n, 7, 1.02 * p.diameter);
  Vector3d c = Vector3d::Zero();
  for (const Vector3d& xi : x) c += xi / n;
  for (const Vector3d& xi : x) s.AddParticle(xi, -0.3 * (xi - c) / std::max((xi - c).norm(), 1e-9));
  s.Finalize(1.5e-5);
  return s;
}

TEST(Dem, ForcesAreEqualAndOppositeSoMomentumIsKept) {
  DemSystem s = Implosion(500, 1);
  const Vector3d p0 = s.Momentum();
  for (int i = 0; i < 1500; ++i) s.Step();
  EXPECT_GT(s.contacts(), 500);  // a packed, cohesive, plastic clump
  const double scale = s.mass() * 0.3 * s.size();
  EXPECT_LT((s.Momentum() - p0).norm(), 1e-12 * scale);
}

TEST(Dem, OneAndTwoThreadsGiveIdenticalStates) {
  DemSystem a = Implosion(3000, 1), b = Implosion(3000, 2);
  for (int i = 0; i < 1500; ++i) {
    a.Step();
    b.Step();
  }
  ASSERT_GT(a.contacts(), 3000);
  ASSERT_GT(a.neighbour_builds(), 1);  // the history survived rebuilds on both
  for (int i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.position(i), b.position(i)) << "particle " << i;
    ASSERT_EQ(a.velocity(i), b.velocity(i)) << "particle " << i;
    ASSERT_EQ(a.plastic_deformation(i), b.plastic_deformation(i)) << "particle " << i;
  }
}

TEST(Dem, StepAboveTheCriticalOneIsRefused) {
  DemSystem s(Nominal(), DemSettings());
  s.AddParticle(Vector3d::Zero());
  const double crit = s.CriticalTimeStep().dt_crit;
  std::printf("critical step of the nominal soil (d %.3f m, f %.2f): %.3g s (%s)\n", Nominal().diameter,
              Nominal().cohesion_factor, crit, s.CriticalTimeStep().element.c_str());
  // independent bound: 12 contacts of k_n on one particle, 2/omega, less for damping
  const SoilParams p = Nominal();
  EXPECT_LT(crit, 2.0 / std::sqrt(12.0 * p.NormalStiffness() / p.Mass()));
  EXPECT_GT(crit, 1.5e-5);  // the paper's step is stable for these particles
  try {
    s.Finalize(1.2 * crit);
    FAIL() << "a step above the critical one was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("critical step"), std::string::npos) << e.what();
  }
}

TEST(Dem, NanIsCaughtNamingStepParticleAndQuantity) {
  DemSystem s = Implosion(100, 1);
  s.Step();
  s.mutable_velocity(5).x() = std::nan("");
  try {
    s.Step();
    FAIL() << "a NaN velocity went through";
  } catch (const SimulationError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("DEM step 2"), std::string::npos) << m;
    EXPECT_NE(m.find("particle 5"), std::string::npos) << m;
    EXPECT_NE(m.find("non-finite"), std::string::npos) << m;
  }
}

TEST(Dem, ExcessiveOverlapStopsTheRun) {
  DemSystem s(Nominal(), DemSettings());
  s.set_gravity(Vector3d::Zero());
  s.AddParticle(Vector3d::Zero());
  s.AddParticle(Vector3d(0.65 * 0.03, 0, 0));  // 35 % of the diameter: beyond the 25 % limit
  s.Finalize(1e-5);
  try {
    s.Step();
    FAIL() << "a 35 % overlap went through";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("overlaps a neighbour or a wall by 0.34"), std::string::npos) << e.what();
  }
}

// one particle dropped onto a single triangle above its face, an edge and a vertex: it comes to
// rest with the wall carrying exactly its weight (plasticity off: a particle this lightly loaded
// keeps re-expanding at V_relax under eq. 16, see PouredBedSettles)
TEST(Dem, ParticleRestsOnATriangleFaceEdgeAndVertex) {
  SoilParams p = Nominal();
  p.plasticity = false;
  const double r = 0.5 * p.diameter;
  const Vector3d spots[] = {{0.2, 0.2, 0}, {0.5, 0.0, 0}, {0.0, 0.0, 0}};
  for (const Vector3d& at : spots) {
    DemSystem s(p, DemSettings());
    DemWall tri;
    tri.name = "triangle";
    tri.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tri.mesh.faces = {{0, 1, 2}};
    s.AddWall(tri);
    s.AddParticle(at + Vector3d(0, 0, r + 0.002));
    s.Finalize(1.5e-5);
    for (int i = 0; i < 40000; ++i) s.Step();  // 0.6 s
    const double weight = p.Mass() * 9.81;
    EXPECT_NEAR(s.wall(0).force.z(), -weight, 1e-6 * weight) << at.transpose();
    EXPECT_NEAR(s.wall(0).force.head<2>().norm(), 0.0, 1e-9 * weight) << at.transpose();
    EXPECT_LT(s.velocities()[0].norm(), 1e-6) << at.transpose();
    EXPECT_NEAR(s.positions()[0].x(), at.x(), 1e-9);
    // resting depth: repulsion starts at d0, carries the weight with k_n, plus the plastic flattening
    const double d = p.adhesion_depth * p.diameter + weight / p.NormalStiffness() + s.plastic_deformation(0);
    EXPECT_NEAR(s.positions()[0].z(), r - d, 1e-9) << at.transpose();
  }
}

// Particles resting on a floor under gravity tilted 10 deg (below the wall's friction angle,
// atan 0.5) are held by their wall contacts' anchor springs alone. A particle far from them (falling
// beside the floor), moved from one end of the row to the other, makes a neighbour build that renumbers every slot
// (it goes from the first slot to the last and back), and the springs must follow their
// particles through it (WallContacts::PermuteSlots). Each particle then stays where it was, and
// the floor carries the weight's slope component (pushed down the slope, +x): had a build lost the springs, a particle would
// slip until its spring took up m g sin(theta) again, by about m g sin(theta) / k_t.
TEST(Dem, WallContactSpringsFollowTheirParticlesThroughABuild) {
  SoilParams p = Nominal();
  p.plasticity = false;
  const double D = p.diameter, r = 0.5 * D, theta = 10.0 * M_PI / 180.0, L = 20 * 1.5 * D;
  DemSystem s(p, DemSettings());
  s.set_gravity(9.81 * Vector3d(std::sin(theta), 0, -std::cos(theta)));
  s.AddWall(MakeQuadWall("floor", {-D, -D, 0}, {L + 2 * D, 0, 0}, {0, 2 * D, 0}));
  const int sentinel = s.AddParticle(Vector3d(-0.3, 0, 0.5));
  std::vector<int> row;
  for (int k = 0; k < 20; ++k) row.push_back(s.AddParticle(Vector3d(k * 1.5 * D, 0, r - 0.2 * p.adhesion_depth * D)));
  s.Finalize(1.5e-5);
  for (int i = 0; i < 20000; ++i) s.Step();  // 0.3 s: at rest
  const double weight = p.Mass() * 9.81;
  std::vector<Vector3d> x0;
  for (int id : row) {
    x0.push_back(s.position(id));
    ASSERT_LT(s.velocity(id).norm(), 1e-6);
  }
  ASSERT_NEAR(s.wall(0).force.x(), 20 * weight * std::sin(theta), 1e-6 * weight);
  // what a lost spring would cost: the static stretch of one
  const double slip = weight * std::sin(theta) / p.TangentialStiffness();
  const long builds = s.neighbour_builds();
  for (int k = 0; k < 6; ++k) {
    s.mutable_position(sentinel) = Vector3d(k % 2 ? -0.3 : L + 0.3, 0, 0.5);
    s.mutable_velocity(sentinel).setZero();
    for (int i = 0; i < 200; ++i) s.Step();
  }
  EXPECT_GE(s.neighbour_builds() - builds, 6);
  for (size_t k = 0; k < row.size(); ++k) {
    EXPECT_LT((s.position(row[k]) - x0[k]).norm(), 1e-3 * slip) << k;
    EXPECT_LT(s.velocity(row[k]).norm(), 1e-6) << k;
  }
  EXPECT_NEAR(s.wall(0).force.x(), 20 * weight * std::sin(theta), 1e-6 * weight);
}

// A 0.1 m particle pressed onto a floor tilted 15 deg (below the wall's friction angle, atan 0.5)
// with 50 times its weight (about the lid's 33 kPa on its cross-section, the load of a consolidated
// bed's contacts), started sliding down at 1 m/s, at the tiny levels' step (1.2e-4 s). Coulomb
// friction stops it after v0^2 / (2 a), a = g' (mu cos - sin), and holds it. At this load the Coulomb
// element's dashpot mu F / v_slip is 30 times too stiff for an explicit step: stepped explicitly,
// it reversed the sliding every step, each reversal reset the anchor, and the particle never
// stuck (AsperityFriction::CoulombDamping).
TEST(Dem, APressedParticleStopsWhereCoulombSaysAndSticksAtACoarseStep) {
  SoilParams p = Nominal();
  p.plasticity = false;
  p.cohesion = false;
  p.diameter = 0.1;
  const double theta = 15.0 * M_PI / 180.0, mu = 0.5, g = 50.0 * 9.81, v0 = 1.0, dt = 1.2e-4;
  DemSystem s(p, DemSettings());
  s.set_gravity(g * Vector3d(std::sin(theta), 0, -std::cos(theta)));
  DemWall floor = MakeQuadWall("floor", {-0.5, -0.5, 0}, {2.0, 0, 0}, {0, 1.0, 0});
  floor.friction = mu;
  s.AddWall(std::move(floor));
  // resting on the floor at the depth that carries the load (d0 plus the load over k_n)
  const double f_n = p.Mass() * g * std::cos(theta);
  const double depth = p.adhesion_depth * p.diameter + f_n / p.NormalStiffness();
  const int id = s.AddParticle(Vector3d(0, 0, 0.5 * p.diameter - depth));
  s.Finalize(dt);
  ASSERT_GT(mu * f_n / p.slip_velocity * dt / p.Mass(), 20.0);  // the explicit dashpot's c dt / m
  for (int i = 0; i < 2000; ++i) s.Step();  // settle on the floor, held by the spring
  ASSERT_LT(s.velocity(id).norm(), 1e-4);
  const Vector3d x0 = s.position(id);
  s.mutable_velocity(id) = Vector3d(v0, 0, 0);
  const double a = g * (mu * std::cos(theta) - std::sin(theta));
  for (int i = 0; i < static_cast<int>(0.1 / dt); ++i) s.Step();  // 11 stopping times
  EXPECT_LT(s.velocity(id).norm(), 1e-4);
  // the stopping distance, within what the spring's change of load (mu F sliding, m g' sin at rest)
  // and one step's travel leave open
  const double travel = s.position(id).x() - x0.x();
  const double spring = (mu * f_n - p.Mass() * g * std::sin(theta)) / p.TangentialStiffness();
  EXPECT_NEAR(travel, v0 * v0 / (2.0 * a), spring + v0 * dt) << "stopping distance";
  // and it stays: 0.5 s more moves it less than a thousandth of the stopping distance
  const Vector3d x1 = s.position(id);
  for (int i = 0; i < static_cast<int>(0.5 / dt); ++i) s.Step();
  EXPECT_LT((s.position(id) - x1).norm(), 1e-3 * v0 * v0 / (2.0 * a));
  EXPECT_LT(s.velocity(id).norm(), 1e-4);
}

// a few hundred particles poured into a box come to rest: slow (under 1e-3 m/s, with plasticity at
// f = 0.05, 1 and 3 and without it), barely overlapping, the walls carrying the whole weight.
DemSystem PourIntoABox(bool plasticity, double* vmax, double* overlap, double* carried_fraction, double f = 1.0) {
  SoilParams p = Nominal();
  p.plasticity = plasticity;
  p.cohesion_factor = f;
  const double D = p.diameter, L = 10 * 1.05 * D;
  DemSettings st;
  st.threads = 2;
  DemSystem s(p, st);
  for (DemWall& w : MakeOpenBoxWalls(L, L, L)) s.AddWall(std::move(w));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02 * D, 0.02 * D);
  // staggered layers (10 x 10 and 9 x 9, each over the hollows of the one below): a simple-cubic
  // stack is metastable and, once plastic flattening lets it buckle, collapses in stages for
  // seconds (the settling then measures the lattice, not the law)
  for (int k = 0; k < 4; ++k) {
    const int m = k % 2 ? 9 : 10;
    const double o = k % 2 ? 1.0 : 0.5;
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i)
        s.AddParticle(Vector3d((i + o) * 1.05 * D + u(rng), (j + o) * 1.05 * D + u(rng), (k + 0.6) * 1.1 * D));
  }
  s.Finalize(1.5e-5);
  // 1 s (the time a consolidated bed has to come to rest, issue 49); the wall load averaged over
  // the last 0.06 s
  Vector3d carried = Vector3d::Zero();
  for (int i = 0; i < 66667; ++i) {
    s.Step();
    if (i >= 62667)
      for (int w = 0; w < s.num_walls(); ++w) carried += s.wall(w).force / 4000.0;
  }
  *vmax = 0.0;
  for (const Vector3d& v : s.velocities()) *vmax = std::max(*vmax, v.norm());
  *overlap = 0.0;
  const std::vector<Vector3d> x = s.positions();
  // the effective penetration of each pair: its overlap less both particles' plastic flattening
  for (int i = 0; i < s.size(); ++i)
    for (int j = i + 1; j < s.size(); ++j)
      *overlap = std::max(*overlap, (D - (x[i] - x[j]).norm() - s.plastic_deformation(i) - s.plastic_deformation(j)) / D);
  *carried_fraction = -carried.z() / (s.size() * p.Mass() * 9.81);
  return s;
}

TEST(Dem, PouredBedSettles) {
  double vmax, overlap, carried;
  PourIntoABox(false, &vmax, &overlap, &carried);
  // pairs rest at the adhesion's reach d0 (fig. 7), plus the elastic give under the weight above:
  // the whole 4-particle column on one contact is 4 m g / k_n = 3.2e-5 d; allowed 1e-3 d
  const SoilParams p = Nominal();
  const double elastic = 4 * p.Mass() * 9.81 / (p.NormalStiffness() * p.diameter);
  ASSERT_LT(elastic, 1e-4);
  const double rest = p.adhesion_depth + 1e-3;
  std::printf("no plasticity, f = 1: fastest particle %.3g m/s, largest effective overlap %.4f d\n", vmax, overlap);
  EXPECT_LT(vmax, 1e-3);
  EXPECT_LT(overlap, rest);
  EXPECT_NEAR(carried, 1.0, 0.01);
  for (const double f : {0.05, 1.0, 3.0}) {
    PourIntoABox(true, &vmax, &overlap, &carried, f);
    std::printf("plasticity, f = %.2f: fastest particle %.3g m/s, largest effective overlap %.4f d, walls carry %.4f\n", f,
                vmax, overlap, carried);
    // (a particle pulled apart gives back plastic deformation at up to V_relax, 0.045 m/s, where
    // that releases energy; by the end of the second every particle is at rest: 9e-6, 8e-6 and
    // 6.4e-4 m/s at f = 0.05, 1, 3)
    EXPECT_LT(vmax, 1e-3) << "f = " << f;
    // beyond both particles' plastic flattening; at f = 3 a bonded bed holds stresses of its own
    // (a contact's repulsion against its particle's adhesive pulls: two of f x fig. 10's 1.5e4 Pa
    // x A at f = 3 are 0.2 % of d in k_n): the deepest sits 0.15 % of d further in
    EXPECT_LT(overlap, rest + (f > 1.0 ? 2e-3 : 0.0)) << "f = " << f;
    EXPECT_NEAR(carried, 1.0, 0.01) << "f = " << f;
  }
}

// A fast wall (a wheel) moves through the bed with wall-only candidate builds: sweeping a plate at
// 4 m/s through a row of free particles, it strikes every one of them (none passes through it), as
// a slow wall, which forces full neighbour builds, does (the same states to round-off); and it
// forces fewer neighbour builds.
TEST(Dem, FastWallStrikesEveryParticleWithWallOnlyBuilds) {
  struct Run {
    std::vector<Vector3d> x, v;
    long neighbour_builds = 0, wall_builds = 0;
    double plate_x = 0.0;
  };
  auto run = [](bool fast) {
    DemSystem s(Elastic(0.0), DemSettings());
    s.set_gravity(Vector3d::Zero());
    DemWall plate = MakeQuadWall("plate", {0, -0.1, -0.1}, {0, 0.2, 0}, {0, 0, 0.2});
    plate.position = Vector3d(-0.1, 0, 0);
    plate.velocity = Vector3d(4.0, 0, 0);
    plate.friction = 0.0;
    plate.fast = fast;
    const int w = s.AddWall(plate);
    for (int k = 0; k < 6; ++k) s.AddParticle(Vector3d(0.05 + 0.08 * k, 0.02 * (k % 3) - 0.02, 0.0));
    const double dt = 0.5 * s.CriticalTimeStep().dt_crit;
    s.Finalize(dt);
    const long builds0 = s.neighbour_builds();
    while (s.wall(w).position.x() < 0.5) {
      s.mutable_wall(w).position.x() += 4.0 * dt;
      s.Step();
    }
    Run r{s.positions(), s.velocities(), s.neighbour_builds() - builds0, s.wall_builds(), s.wall(w).position.x()};
    return r;
  };
  const Run fast = run(true), slow = run(false);
  const double radius = 0.5 * Elastic(0.0).diameter;
  for (size_t i = 0; i < fast.x.size(); ++i) {
    // struck: ahead of the plate (none passed through it), driven forward
    EXPECT_GT(fast.x[i].x(), fast.plate_x + 0.9 * radius) << "particle " << i;
    EXPECT_GT(fast.v[i].x(), 1.0) << "particle " << i;
    EXPECT_NEAR((fast.x[i] - slow.x[i]).norm(), 0.0, 1e-9) << "particle " << i;
    EXPECT_NEAR((fast.v[i] - slow.v[i]).norm(), 0.0, 1e-9) << "particle " << i;
  }
  // the slow plate rebuilt the lists every half skin it moved; the fast one only its candidates
  EXPECT_LT(fast.neighbour_builds, slow.neighbour_builds);
  EXPECT_GT(fast.wall_builds, fast.neighbour_builds);
}

// A slow wall's candidates are the triangles within d / 2 + the skin of a particle (its default
// margin): a particle touches a wall only within d / 2 of it, a slow wall that moves half the skin
// rebuilds the neighbour lists and its candidates, and a wall-only build follows whenever the wall
// and the particles together have moved more than the margin since the last one. A cohesive,
// plastic bed in a box under a lid pressing down into it gets the same forces, bit for bit, every
// step, as with the margin of before (cutoff - d / 2: six times the skin), from fewer candidates.
TEST(Dem, ASlowWallsCandidatesWithinTheSkinGiveTheForcesOfAWideMargin) {
  struct Run {
    std::vector<Vector3d> x, v, lid, floor;
    long candidates = 0, wall_builds = 0;
  };
  const SoilParams p = Nominal();
  const double d = p.diameter;
  auto run = [&](double margin) {
    DemSystem s(p, DemSettings());
    std::vector<DemWall> box = {MakeQuadWall("floor", {-d, -d, 0}, {8 * d, 0, 0}, {0, 8 * d, 0}),
                                MakeQuadWall("left", {-d, -d, 0}, {0, 0, 6 * d}, {8 * d, 0, 0}),
                                MakeQuadWall("front", {-d, -d, 0}, {0, 8 * d, 0}, {0, 0, 6 * d})};
    const double top = 3.0 * d;  // the lattice's top particles' tops
    DemWall lid = MakeQuadWall("lid", {-d, -d, 0}, {0, 8 * d, 0}, {8 * d, 0, 0});  // (facing down)
    lid.position = Vector3d(0, 0, top + 0.02 * d);
    const double speed = 0.5 * d;  // [m/s] down: 0.3 d into the bed in 0.6 s
    lid.velocity = Vector3d(0, 0, -speed);
    box.push_back(lid);
    int w_lid = -1, w_floor = -1;
    for (DemWall& w : box) {
      w.margin = margin;
      const int k = s.AddWall(w);
      if (w.name == "lid") w_lid = k;
      if (w.name == "floor") w_floor = k;
    }
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        for (int k = 0; k < 3; ++k)
          s.AddParticle(Vector3d((i + 0.5 + 0.02 * (j % 3)) * d, (j + 0.5) * d, (k + 0.5) * d));
    const double dt = 0.5 * s.CriticalTimeStep().dt_crit;
    s.Finalize(dt);
    Run r;
    for (int n = 0; n < static_cast<int>(0.6 / dt); ++n) {
      s.mutable_wall(w_lid).position.z() -= speed * dt;
      s.Step();
      r.lid.push_back(s.wall(w_lid).force);
      r.floor.push_back(s.wall(w_floor).force);
      r.candidates = std::max(r.candidates, s.wall_candidates());
    }
    r.x = s.positions();
    r.v = s.velocities();
    r.wall_builds = s.wall_builds();
    return r;
  };
  const Run skin = run(0.0), wide = run(0.6 * d);
  std::printf("wall candidates (most at a build): %ld within the skin, %ld within 0.6 d; wall builds %ld and %ld; "
              "the lid's last force %.1f N\n",
              skin.candidates, wide.candidates, skin.wall_builds, wide.wall_builds, skin.lid.back().z());
  EXPECT_GT(skin.lid.back().z(), 10.0 * p.Mass() * 9.81);  // it did press into the bed
  EXPECT_LT(skin.candidates, wide.candidates);
  for (size_t n = 0; n < skin.lid.size(); ++n) {
    ASSERT_EQ(skin.lid[n], wide.lid[n]) << "step " << n;
    ASSERT_EQ(skin.floor[n], wide.floor[n]) << "step " << n;
  }
  for (size_t i = 0; i < skin.x.size(); ++i) {
    EXPECT_EQ(skin.x[i], wide.x[i]) << "particle " << i;
    EXPECT_EQ(skin.v[i], wide.v[i]) << "particle " << i;
  }
}

// A fast wall's displacement since its build (what decides its candidates' next build) is bounded
// from its pose, |p - p_b| + ||R - R_b||_F max|v|, without its vertices: never below any vertex's
// distance, whatever the motion; exact for a translation; for a turn by theta about an axis square
// to a farthest vertex, sqrt(2) times that vertex's 2 r sin(theta / 2) (||R - R_b||_F =
// 2 sqrt(2) sin(theta / 2)). A slow wall's is its vertices' own largest distance.
TEST(Dem, AFastWallsDisplacementBoundsEveryVertexFromItsPose) {
  const SoilParams p = Nominal();
  // a ring of vertices at radius 0.45 m in the x-z plane (a wheel turning about y), two off-plane
  std::vector<Vector3d> v;
  for (int k = 0; k < 24; ++k) v.push_back(0.45 * Vector3d(std::cos(k * M_PI / 12), 0.0, std::sin(k * M_PI / 12)));
  v.push_back({0.1, 0.2, 0.05});
  v.push_back({-0.2, -0.15, 0.1});
  auto wall = [&](bool fast) {
    DemWall w;
    w.name = fast ? "fast" : "slow";
    w.mesh.vertices = v;
    for (int k = 0; k + 2 < static_cast<int>(v.size()); ++k) w.mesh.faces.push_back({k, k + 1, k + 2});
    w.position = Vector3d(12.0, -3.0, 0.6);
    w.fast = fast;
    return w;
  };
  const double r = 0.45;
  WallContacts walls(1.1 * p.diameter, p.diameter);
  const int fast = walls.Add(wall(true), p, 0), slow = walls.Add(wall(false), p, 0);
  const ParticleStore none;
  walls.Build(none, 1, 0.0);
  const Vector3d p_b = walls.wall(fast).position;
  const Eigen::Matrix3d R_b = walls.wall(fast).rotation;
  auto move = [&](const Vector3d& dp, const Eigen::Matrix3d& dR) {
    for (int w : {fast, slow}) {
      walls.wall(w).position = p_b + dp;
      walls.wall(w).rotation = dR * R_b;
    }
    walls.UpdateVertices();
    double most = 0.0;  // the largest distance of a vertex from where it was at the build
    for (const Vector3d& u : v) most = std::max(most, ((p_b + dp) + dR * R_b * u - (p_b + R_b * u)).norm());
    return most;
  };
  // a translation: the bound is the distance moved
  double most = move(Vector3d(0.003, -0.001, 0.002), Eigen::Matrix3d::Identity());
  EXPECT_NEAR(walls.WallDisplacement(fast), most, 3e-11);  // (the round-off margin: 1e-12 (|p| + |p_b| + r))
  EXPECT_NEAR(walls.WallDisplacement(slow), most, 1e-15);
  // a turn about y (the ring's axis): sqrt(2) times the rim's chord
  for (double theta : {1e-4, 0.01, 0.3}) {
    most = move(Vector3d::Zero(), Eigen::AngleAxisd(theta, Vector3d::UnitY()).toRotationMatrix());
    EXPECT_NEAR(most, 2.0 * r * std::sin(0.5 * theta), 1e-12);
    EXPECT_NEAR(walls.WallDisplacement(fast), std::sqrt(2.0) * most, 3e-11 + 1e-9 * most) << theta;
    EXPECT_NEAR(walls.WallDisplacement(slow), most, 1e-12) << theta;
  }
  // random rigid motions: never below any vertex's distance
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const double scale = std::pow(10.0, -6.0 + 5.0 * (0.5 + 0.5 * u(rng)));
    const Vector3d dp = scale * Vector3d(u(rng), u(rng), u(rng));
    const Vector3d axis = Vector3d(u(rng), u(rng), u(rng)).normalized();
    most = move(dp, Eigen::AngleAxisd(scale * 10.0 * u(rng), axis).toRotationMatrix());
    ASSERT_GE(walls.WallDisplacement(fast), most) << k;
  }
}

}  // namespace
}  // namespace dem_mobility::core
