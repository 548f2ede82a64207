// The DEM solver's particle bookkeeping and energy ledger: particles added and removed between steps
// without a full rebuild (against a system that rebuilt), stable IDs, determinism of an emit/remove
// stream across thread counts, the work of a moving wall and the dissipation of a damped
// collision against their analytic values, and the plastic ledger closing the energy balance of an
// undamped plastic clump.
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <random>

#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

// a 6 x 6 x 3 lattice of cohesive particles on a floor, touching (1 % overlap), settled a little
DemSystem SmallBed(int slack, int threads) {
  const SoilParams p = Nominal();
  const double D = p.diameter, a = 0.99 * D;
  DemSettings st;
  st.list_slack = slack;
  st.threads = threads;
  DemSystem s(p, st);
  s.AddWall(MakeQuadWall("floor", {-D, -D, 0}, {8 * D, 0, 0}, {0, 8 * D, 0}));
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i) s.AddParticle(Vector3d(i * a, j * a, 0.495 * D + k * a));
  s.Finalize(1.5e-5);
  for (int i = 0; i < 2000; ++i) s.Step();
  return s;
}

TEST(DemParticles, AddingAParticleExtendsTheListsWithoutARebuild) {
  // A has room in its lists, B none: A takes the new particle in place, B rebuilds everything;
  // both must then move the same (to round-off: the force sums may run in another order)
  DemSystem a = SmallBed(4, 1), b = SmallBed(0, 1);
  const double D = a.soil().diameter;
  const Vector3d top = a.position(3 * 36 - 1) + Vector3d(0, 0, 0.99 * D);  // on the last particle
  const long builds_a = a.neighbour_builds(), builds_b = b.neighbour_builds();
  const int id_a = a.AddParticle(top, Vector3d(0, 0, -0.05));
  const int id_b = b.AddParticle(top, Vector3d(0, 0, -0.05));
  EXPECT_EQ(id_a, 108);
  EXPECT_EQ(id_b, 108);
  EXPECT_EQ(a.neighbour_builds(), builds_a) << "an added particle must not rebuild the lists";
  ASSERT_EQ(b.neighbour_builds(), builds_b + 1) << "B was meant to overflow its lists";
  EXPECT_EQ(b.overflow_builds(), 1);
  for (int i = 0; i < 3000; ++i) {
    a.Step();
    b.Step();
  }
  EXPECT_GT(a.contacts(), 0);
  EXPECT_EQ(a.contacts(), b.contacts());
  double worst = 0.0;
  for (int id = 0; id < a.size(); ++id) worst = std::max(worst, (a.position(id) - b.position(id)).norm());
  EXPECT_LT(worst, 1e-9 * D);
  // it lands on the bed and stays there (adhesion holds it; it neither sinks in nor bounces off):
  // after 0.3 s more it rests on the particle below at the adhesion's reach d0 (fig. 7) plus both
  // particles' plastic flattening
  for (int i = 0; i < 20000; ++i) a.Step();
  const int below = 3 * 36 - 1;
  const double gap = D * (1.0 - a.soil().adhesion_depth) - a.plastic_deformation(id_a) - a.plastic_deformation(below);
  EXPECT_NEAR((a.position(id_a) - a.position(below)).norm(), gap, 1e-3 * D);
  EXPECT_LT(a.velocity(id_a).norm(), 1e-3);
}

TEST(DemParticles, RemovingTheParticleBelowLetsTheOneAboveFall) {
  SoilParams p = Elastic(2.1e4);
  const double D = p.diameter;
  DemSystem s(p, DemSettings());
  s.AddWall(MakeQuadWall("floor", {-D, -D, 0}, {2 * D, 0, 0}, {0, 2 * D, 0}));
  const int below = s.AddParticle(Vector3d(0, 0, 0.5 * D));
  const int above = s.AddParticle(Vector3d(0, 0, 1.5 * D));
  s.Finalize(1.5e-5);
  for (int i = 0; i < 20000; ++i) s.Step();  // settled: the lower one carries the upper one
  ASSERT_LT(s.velocity(above).norm(), 1e-6);
  const Vector3d resting = s.position(below);
  s.RemoveParticle(below);
  EXPECT_FALSE(s.alive(below));
  EXPECT_EQ(s.num_alive(), 1);
  EXPECT_EQ(s.position(below), resting);  // its last state stays readable
  s.Step();  // the first half-kick still uses the old contact force
  const double v1 = s.velocity(above).z();
  for (int i = 0; i < 100; ++i) s.Step();
  // free fall: no force but its weight
  EXPECT_NEAR(s.velocity(above).z() - v1, -9.81 * 100 * s.dt(), 1e-12);
  EXPECT_EQ(s.contacts(), 0);
  // its storage is reused by the next particle, under a new ID
  const int again = s.AddParticle(Vector3d(0, 0, 0.5 * D));
  EXPECT_EQ(again, 2);
  EXPECT_TRUE(std::isnan(s.position(below).x()));
  EXPECT_THROW(s.RemoveParticle(below), ConfigError);
}

// Every step's force starts at each particle's weight (the step's final pass starts the next
// step's sums): a particle added between steps, into a freed slot or appended, falls freely from
// its first step (two half kicks of its weight: g dt), and a gravity changed between steps acts
// from the next force evaluation on (the first half kick still has the old weight)
TEST(DemParticles, AddedParticlesAndAChangedGravityActFromTheNextStep) {
  const SoilParams p = Nominal();
  DemSystem s(p, DemSettings());
  for (int k = 0; k < 3; ++k) s.AddParticle(Vector3d(k, 0, 0));  // far apart: no contacts
  s.Finalize(1e-5);
  const double dt = s.dt();
  for (int i = 0; i < 10; ++i) s.Step();
  const Vector3d g(0, 0, -9.81);
  auto falls_freely = [&](int id, const char* what) {
    EXPECT_NEAR((s.velocity(id) - dt * g).norm(), 0.0, 1e-12 * dt * g.norm()) << what << ": " << s.velocity(id).transpose();
  };
  s.RemoveParticle(1);
  const int reused = s.AddParticle(Vector3d(5, 0, 0));  // the freed slot
  s.Step();
  falls_freely(reused, "in a freed slot");
  EXPECT_EQ(s.contacts(), 0);
  const int appended = s.AddParticle(Vector3d(7, 0, 0));
  s.Step();
  falls_freely(appended, "appended");
  s.RemoveParticle(0);
  const int again = s.AddParticle(Vector3d(9, 0, 0));  // the freed slot, one more step on
  s.Step();
  falls_freely(again, "in a freed slot after an append");
  // gravity changed between steps: dv = (g_old + g_new) dt / 2 in the next step
  const Vector3d g2(1.0, 0, -3.0), v0 = s.velocity(2);
  s.set_gravity(g2);
  s.Step();
  EXPECT_NEAR((s.velocity(2) - v0 - 0.5 * dt * (g + g2)).norm(), 0.0, 1e-12) << s.velocity(2).transpose();
  const Vector3d v1 = s.velocity(2);
  s.Step();
  EXPECT_NEAR((s.velocity(2) - v1 - dt * g2).norm(), 0.0, 1e-12) << s.velocity(2).transpose();
}

// a moving soil patch in miniature: particles rained into a box and the oldest removed
DemSystem Stream(int threads, long* adds) {
  const SoilParams p = Nominal();
  const double D = p.diameter, L = 8 * D;
  DemSettings st;
  st.threads = threads;
  st.serial_below = 0;  // 100 particles: on `threads` all the same, to test them
  DemSystem s(p, st);
  for (DemWall& w : MakeOpenBoxWalls(L, L, L)) s.AddWall(std::move(w));
  // 25 emission points, each used every 1000 steps, high above the columns that pile up below them
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.1 * D, 0.1 * D);
  s.AddParticle(Vector3d(0.5 * L, 0.5 * L, 0.5 * D));
  s.Finalize(1.5e-5);
  int oldest = 0;
  *adds = 0;
  for (int i = 0; i < 12000; ++i) {
    if (i % 40 == 0) {
      const int spot = static_cast<int>(*adds % 25);
      s.AddParticle(Vector3d((1.2 + 1.4 * (spot % 5)) * D + jitter(rng), (1.2 + 1.4 * (spot / 5)) * D + jitter(rng), 10 * D),
                    Vector3d(0, 0, -3.0));
      ++*adds;
    }
    if (i % 40 == 20 && s.num_alive() > 100) s.RemoveParticle(oldest++);
    s.Step();
  }
  return s;
}

TEST(DemParticles, EmitAndRemoveStreamIsDeterministicAcrossThreads) {
  long adds1, adds2;
  const DemSystem a = Stream(1, &adds1), b = Stream(2, &adds2);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.num_alive(), 100);
  for (int id = 0; id < a.size(); ++id) {
    if (!a.alive(id)) continue;
    ASSERT_EQ(a.position(id), b.position(id)) << "particle " << id;
    ASSERT_EQ(a.velocity(id), b.velocity(id)) << "particle " << id;
  }
  // adding does not rebuild the lists (only a neighbour's full list would: none is full here)
  std::printf("%ld added, %ld neighbour builds, %ld of them for a full list\n", adds1, a.neighbour_builds(), a.overflow_builds());
  EXPECT_EQ(a.overflow_builds(), 0) << adds1 << " added, " << a.neighbour_builds() << " builds";
  EXPECT_EQ(b.overflow_builds(), 0);
  const EnergyReport e = a.Energy();
  EXPECT_GT(e.dissipated, 0.0);
}

TEST(DemParticles, WallWorkEqualsTheEnergyAPistonGives) {
  // an undamped frictionless particle bouncing off a wall moving toward it: in the wall's frame
  // it reverses its speed, so it leaves at 2U - v, and the wall's work is the kinetic energy gained
  const SoilParams p = Elastic(0.0);
  const double D = p.diameter, m = p.Mass(), v = -0.2, U = 0.3;
  DemSystem s(p, DemSettings());
  s.set_gravity(Vector3d::Zero());
  const int wall = s.AddWall(MakeQuadWall("piston", {0, -D, -D}, {0, 2 * D, 0}, {0, 0, 2 * D}));
  const int id = s.AddParticle(Vector3d(0.5 * D + 0.002, 0, 0), Vector3d(v, 0, 0));
  s.mutable_wall(wall).velocity = Vector3d(U, 0, 0);
  const double dt = 0.02 * 2.0 * std::sqrt(m / p.NormalStiffness());
  s.Finalize(dt);
  double X = 0.0;
  for (int i = 0; i < 100000; ++i) {
    X += U * dt;
    s.mutable_wall(wall).position = Vector3d(X, 0, 0);
    s.Step();
    if (s.velocity(id).x() > 0.0 && s.position(id).x() - X > 0.5 * D + 1e-4) break;  // parted
  }
  const double v_out = 2 * U - v;
  EXPECT_NEAR(s.velocity(id).x(), v_out, 1e-3 * v_out);
  const EnergyReport e = s.Energy();
  const double gained = 0.5 * m * (v_out * v_out - v * v);
  EXPECT_NEAR(e.wall_work, gained, 2e-3 * gained);
  EXPECT_NEAR(e.dissipated, 0.0, 2e-3 * gained);
}

TEST(DemParticles, DissipationOfADampedCollisionIsTheKineticEnergyLost) {
  const SoilParams p = Elastic(2.1e4);
  const double D = p.diameter, m = p.Mass(), v0 = 0.5;
  const double m_eff = 0.5 * m, k = p.NormalStiffness(), c = p.NormalDamping();
  const double zeta = c / (2.0 * std::sqrt(k * m_eff));
  const double e = std::exp(-M_PI * zeta / std::sqrt(1.0 - zeta * zeta));
  DemSystem s(p, DemSettings());
  s.set_gravity(Vector3d::Zero());
  s.AddParticle(Vector3d(-0.5 * D - 1e-4, 0, 0), Vector3d(v0, 0, 0));
  s.AddParticle(Vector3d(0.5 * D + 1e-4, 0, 0), Vector3d(-v0, 0, 0));
  s.Finalize(0.02 * 2.0 * std::sqrt(m_eff / k));
  for (int i = 0; i < 200000 && !(s.position(1).x() - s.position(0).x() > D + 2e-4); ++i) s.Step();
  const double lost = m * v0 * v0 * (1.0 - e * e);  // two particles, each from v0 to e v0
  EXPECT_NEAR(s.Energy().dissipated, lost, 0.02 * lost);
  EXPECT_EQ(s.Energy().wall_work, 0.0);
}


// The plastic ledger (set_plastic_ledger): particles thrown together with cohesion and plasticity
// on, but no dampers and no friction. Between the plastic updates the contact forces are
// conservative (the repulsion and the adhesion triangle at fixed deformations), and each update
// changes the stored energy at fixed positions: with the ledger, the mechanical energy changes by
// the ledger's plastic exchange, and what is left as dissipated is the integrator's error. That
// error is of first order in the step (the half kicks about an update use the force of the old
// deformation on one side and of the new one on the other), so halving the step halves it; without
// the ledger, the dissipated energy is minus the exchange at any step.
TEST(DemParticles, ThePlasticLedgerClosesTheBalanceOfAnUndampedPlasticClump) {
  SoilParams p = Nominal();
  p.damping_area = 0.0;
  p.separation_factor = 1.0;
  p.friction = 0.0;
  p.viscosity = 0.0;
  const double D = p.diameter;
  // the clump over the same simulated time at a step of `fraction` of the critical one
  auto clump = [&](bool ledger, double fraction) {
    DemSettings st;
    st.max_overlap = 0.3;
    DemSystem s(p, st);
    s.set_gravity(Vector3d::Zero());
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    const int side = 6;
    const Vector3d c = 0.5 * (side - 1) * 1.02 * D * Vector3d::Ones();
    for (int i = 0; i < side * side * side; ++i) {
      const Vector3d x = 1.02 * D * Vector3d(i % side + u(rng), (i / side) % side + u(rng), i / (side * side) + u(rng));
      s.AddParticle(x, -0.5 * (x - c) / std::max((x - c).norm(), 1e-9));
    }
    s.Finalize(fraction * s.CriticalTimeStep().dt_crit);
    s.set_plastic_ledger(ledger);
    for (long i = 0; i < std::lround(300 / fraction); ++i) s.Step();
    return s;
  };
  const DemSystem a = clump(true, 0.1), b = clump(true, 0.05), off = clump(false, 0.1);
  const double ea = a.Energy().dissipated, eb = b.Energy().dissipated, plastic = b.plastic_exchange();
  std::printf("plastic exchange %.4g J; dissipated with the ledger %.3g J at 0.1 of the critical step, %.3g J at "
              "0.05; without the ledger %.4g J; %d contacts\n",
              plastic, ea, eb, off.Energy().dissipated, b.contacts());
  EXPECT_GT(b.contacts(), 300);
  EXPECT_EQ(b.Energy().wall_work, 0.0);
  EXPECT_LT(std::abs(eb), 0.025 * std::abs(plastic));
  EXPECT_NEAR(eb / ea, 0.5, 0.1);  // first order in the step
  // without the ledger (the same states: the ledger only watches)
  EXPECT_EQ(off.position(0), a.position(0));
  EXPECT_NEAR(off.Energy().dissipated, -a.plastic_exchange(), 0.05 * std::abs(plastic));
}
}  // namespace
}  // namespace dem_mobility::core
