// The cohesive soil particle law (paper section 2.3) against the formulas of the paper and table 2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_energy.h"
#include "dem_mobility/core/dem/soil_law.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {


// table 2: stiffness 4.42e7 N/m^2 (stress per strain) and damping 2.1e4 N s/m^3 on the area of a
// 3 cm particle; these are the numbers the law must use
const double kD = 0.03, kA = M_PI * kD * kD / 4.0;
const double kKn = 4.42e7 * kA / kD, kCn = 2.1e4 * kA;

TEST(SoilLaw, DerivedStiffnessDampingAndMassFollowTable2) {
  const SoilParams p = Nominal();
  EXPECT_NEAR(p.NormalStiffness(), kKn, 1e-9 * kKn);
  EXPECT_NEAR(p.NormalDamping(), kCn, 1e-12 * kCn);
  EXPECT_NEAR(p.Mass(), 1800.0 * M_PI * kD * kD * kD / 6.0, 1e-15);
}

TEST(SoilLaw, NormalForceFollowsTheAdhesionRepulsionCurve) {
  const SoilParams p = Nominal();
  const double d0 = p.adhesion_depth * kD, dp = p.adhesion_peak * kD, fmax = 2.0;  // fig. 7, from the file
  for (int i = -10; i <= 300; ++i) {
    const double x = i * 0.01 * d0;  // from -0.1 d0 (apart) to 3 d0
    const SoilNormalForce f = SoilContactLaw(p).Normal(x, 0.0, fmax);
    double expected = 0.0;
    if (x > 0.0 && x <= dp) expected = -fmax * x / dp;                   // adhesion builds up
    else if (x > dp && x < d0) expected = -fmax * (d0 - x) / (d0 - dp);  // and fades to d0
    else if (x >= d0) expected = kKn * (x - d0);                         // repulsion beyond d0
    EXPECT_NEAR(f.Total(), expected, 1e-9 * (1.0 + std::abs(expected))) << "d = " << x;
    EXPECT_LE(f.adhesion, 0.0);
    EXPECT_GE(f.repulsion, 0.0);
  }
  // the largest pull is exactly the maximum adhesion, at the peak penetration
  EXPECT_NEAR(SoilContactLaw(p).Normal(dp, 0.0, fmax).Total(), -fmax, 1e-12);
}

TEST(SoilLaw, DampingOnApproachAndReducedBySnOnSeparation) {
  const SoilParams p = Nominal();
  const double d = 2.0 * p.adhesion_depth * kD;
  const double elastic = kKn * (d - p.adhesion_depth * kD);
  EXPECT_NEAR(SoilContactLaw(p).Normal(d, 0.5, 0.0).Total(), elastic + kCn * 0.5, 1e-9);
  EXPECT_NEAR(SoilContactLaw(p).Normal(d, -0.5, 0.0).Total(), elastic - 0.1 * kCn * 0.5, 1e-9);
  // out of contact: nothing, whatever the rate
  EXPECT_EQ(SoilContactLaw(p).Normal(-1e-4, 1.0, 5.0).Total(), 0.0);
}

// A particle's drive from contacts of effective penetration d[k] (adhesion: the particle's own
// `a` on each), as the pair sweep sums it.
PlasticDrive DriveOf(const SoilParams& p, const std::vector<double>& d, double a) {
  const SoilContactLaw law(p);
  PlasticDrive drive;
  for (double dk : d) {
    const SoilNormalForce f = law.Normal(dk, 0.0, a);
    drive.max_repulsion = std::max(drive.max_repulsion, f.repulsion);
    drive.normal_sum += f.adhesion + f.repulsion;
    drive.adhesion_reach += dk > 0.0 ? AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, dk) : 0.0;
    drive.contacts += dk > 0.0 ? 1.0 : 0.0;
  }
  return drive;
}

TEST(SoilLaw, PlasticDeformationGrowsAlongFig8AndStaysAfterUnloading) {
  const SoilParams p = Nominal();
  const double d0 = p.adhesion_depth * kD;
  double delta = 0.0;
  // loading: at compressive stress s the deformation is the table's strain times d
  const double stresses[] = {5.0e3, 2.0e4, 3.5e4, 1.0e5};
  const double strains[] = {0.004, 0.012, 0.017, 0.030};  // 3.5e4: halfway between 0.012 and 0.022
  for (int i = 0; i < 4; ++i) {
    delta = UpdatePlasticDeformation(p, delta, MaxAdhesionForce(p, delta),
                                     PlasticDrive{stresses[i] * kA, stresses[i] * kA, 0.0}, 1e-5);
    EXPECT_NEAR(delta, strains[i] * kD, 1e-12) << stresses[i];
  }
  // unloaded to 5e3 Pa (below the 1e5 Pa reached) on two contacts, one pressing and one pulling
  // with the particle's full adhesion: the pull is larger, but giving back deformation would press
  // the compressed contact harder (and weaken both adhesions): it would store energy, so it stays
  // (soil keeps its consolidation after the load is removed, section 2.3)
  const double a = MaxAdhesionForce(p, delta);
  ASSERT_GT(a, 5.0e3 * kA);
  const std::vector<double> pressed = {d0 + 5.0e3 * kA / kKn, p.adhesion_peak * kD};
  const PlasticDrive drive = DriveOf(p, pressed, a);
  ASSERT_LT(drive.normal_sum, 0.0);  // pulled harder than pressed: the old reading relaxed it here
  for (int i = 0; i < 1000; ++i) delta = UpdatePlasticDeformation(p, delta, a, drive, 1e-5);
  EXPECT_NEAR(delta, 0.030 * kD, 1e-12);
}

TEST(SoilLaw, RelaxationWhenPulledApartStopsAtFig8ForThePresentLoad) {
  const SoilParams p = Nominal();
  const double dt = 1e-5;
  double delta = 0.030 * kD;
  // stretched to the adhesion's peak by four contacts (each pulls with the particle's full
  // adhesion, about to break) and pressed lightly by a fifth at 5e3 Pa: giving back deformation
  // releases more energy from the pulls than the adhesion it loses costs, so it relaxes ...
  const SoilContactLaw law(p);
  const double a = MaxAdhesionForce(p, delta);
  const std::vector<double> d = {law.dp, law.dp, law.dp, law.dp, law.d0 + 5.0e3 * kA / kKn};
  const PlasticDrive drive = DriveOf(p, d, a);
  ASSERT_LT(drive.normal_sum, 0.0);
  for (int i = 0; i < 100; ++i) delta = UpdatePlasticDeformation(p, delta, MaxAdhesionForce(p, delta), drive, dt);
  EXPECT_NEAR(delta, 0.030 * kD - 100 * 0.045 * dt, 1e-12);
  // ... at V_relax, down to fig. 8's strain at 5e3 Pa (0.004), where it stops
  for (int i = 0; i < 100000; ++i) delta = UpdatePlasticDeformation(p, delta, MaxAdhesionForce(p, delta), drive, dt);
  EXPECT_NEAR(delta, 0.004 * kD, 1e-12);
}

// Pulled as hard in sum, but by contacts on the falling side of the adhesion triangle (squeezed
// towards d0, far from breaking): the adhesion relaxing would lose costs more than the pulls
// release (fig. 10 rises steeply with the plastic strain), so the deformation stays.
TEST(SoilLaw, NoRelaxationWhereTheAdhesionLostCostsMoreThanThePullsRelease) {
  const SoilParams p = Nominal();
  const SoilContactLaw law(p);
  const double delta = 0.030 * kD, a = MaxAdhesionForce(p, delta);
  const double d_fall = law.d0 - (law.d0 - law.dp) / 3.0;  // a third of the full pull each
  const std::vector<double> d(12, d_fall);
  const PlasticDrive drive = DriveOf(p, d, a);
  ASSERT_NEAR(drive.normal_sum, -4.0 * a, 1e-9 * a);  // as hard as the four peak pulls above
  EXPECT_EQ(UpdatePlasticDeformation(p, delta, a, drive, 1e-5), delta);
}

TEST(SoilLaw, RelaxationAtVrelaxFlooredAtZeroWithoutContacts) {
  const SoilParams p = Nominal();
  double delta = 0.030 * kD;
  const double dt = 1e-5;
  // released (no contact): eq. 16 removes V_relax dt each step (no energy moves)
  for (int i = 0; i < 100; ++i) delta = UpdatePlasticDeformation(p, delta, MaxAdhesionForce(p, delta), {}, dt);
  EXPECT_NEAR(delta, 0.030 * kD - 100 * 0.045 * dt, 1e-12);
  // until nothing is left, and no further
  for (int i = 0; i < 10000; ++i) delta = UpdatePlasticDeformation(p, delta, MaxAdhesionForce(p, delta), {}, dt);
  EXPECT_EQ(delta, 0.0);
  // plasticity off: nothing changes
  SoilParams off = p;
  off.plasticity = false;
  EXPECT_EQ(UpdatePlasticDeformation(off, 0.001, 0.0, PlasticDrive{0.0, -100.0, 0.0}, dt), 0.001);
}

// AdhesionReach is the adhesion triangle's integral: its slope is the triangle, and f_adh_max
// times it is the adhesive part of the contact's normal energy (dem_energy.h).
TEST(SoilLaw, AdhesionReachIsTheTrianglesIntegral) {
  const SoilParams p = Nominal();
  const SoilContactLaw law(p);
  const double fmax = 1.7, h = 1e-9;
  for (int i = -5; i <= 200; ++i) {
    const double d = i * 0.01 * law.d0;
    const double reach = AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d);
    const double slope = (AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d + h) -
                          AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d - h)) / (2 * h);
    EXPECT_NEAR(slope, d > 0.0 ? -law.Normal(d, 0.0, 1.0).adhesion : 0.0, 1e-5) << "d = " << d;
    const double elastic = d > law.d0 ? 0.5 * law.k_n * (d - law.d0) * (d - law.d0) : 0.0;
    EXPECT_NEAR(NormalEnergy(law, d, fmax), d > 0.0 ? elastic - fmax * reach : 0.0, 1e-15) << "d = " << d;
  }
  EXPECT_NEAR(AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, 2.0 * law.d0), 0.5 * law.d0, 1e-18);
}

// The relaxation is dissipative: wherever UpdatePlasticDeformation relaxes a particle, the exact
// energy of its contacts at fixed positions (dem_energy.h's NormalEnergy, the deformation and the
// adhesion changed) falls, to the last bit; where it keeps it, relaxing would have released no
// more than the step's second-order terms. Random contact sets at f = 0.05, 1 and 12, deformations
// from nothing to fig. 10's end.
TEST(SoilLaw, RelaxationNeverStoresEnergyInTheContacts) {
  std::mt19937 rng(7);
  int relaxed = 0, kept = 0;
  for (const double f : {0.05, 1.0, 12.0}) {
    SoilParams p = Nominal();
    p.cohesion_factor = f;
    const SoilContactLaw law(p);
    const double dt = 1e-5, step = p.relax_speed * dt;
    std::uniform_real_distribution<double> pen(-0.2 * law.d0, 1.6 * law.d0), strain(0.0, 0.04);
    std::uniform_int_distribution<int> count(1, 8);
    for (int trial = 0; trial < 4000; ++trial) {
      const double delta = strain(rng) * kD, a = MaxAdhesionForce(p, delta);
      std::vector<double> d(count(rng));
      for (double& x : d) x = pen(rng);
      const PlasticDrive drive = DriveOf(p, d, a);
      // a pure relaxation step (no growth): the present load's fig. 8 value below delta
      if (p.plastic_strain_vs_stress(drive.max_repulsion / p.Area()) * kD > delta - step) continue;
      const double next = UpdatePlasticDeformation(p, delta, a, drive, dt);
      const double a1 = MaxAdhesionForce(p, delta - step);
      double change = 0.0;  // of the contacts' energy, were it to relax
      for (double x : d) change += NormalEnergy(law, x + step, a1) - NormalEnergy(law, x, a);
      // the second-order terms per contact, as the law bounds them (the force's largest slope over
      // the step, k_n or the triangle's a / (d0 - dp), times s^2, and 2 da s) and the triangle's
      // rising side (a / dp, which releases energy)
      const double second =
          d.size() * ((law.k_n + a * std::max(law.inv_dp, law.inv_d0_dp)) * step * step + 2.0 * (a - a1) * step);
      if (next < delta) {
        ++relaxed;
        EXPECT_LE(change, 0.0) << "f " << f << " trial " << trial;
      } else {
        ++kept;
        EXPECT_EQ(next, delta);
        EXPECT_GE(change, -second) << "f " << f << " trial " << trial;
      }
    }
  }
  std::printf("relaxed %d, kept %d of the random contact sets\n", relaxed, kept);
  EXPECT_GT(relaxed, 300);
  EXPECT_GT(kept, 300);
}

TEST(SoilLaw, MaxAdhesionFollowsFig10TimesTheCohesionFactor) {
  SoilParams p = Nominal();
  p.cohesion_factor = 3.0;
  // at the table's points of the file (plastic strain, stress) and halfway between two of them
  const std::vector<double>& e = p.adhesion_stress_vs_plastic_strain.x();
  const std::vector<double>& s = p.adhesion_stress_vs_plastic_strain.y();
  ASSERT_GE(e.size(), 3u);
  EXPECT_NEAR(MaxAdhesionForce(p, e[0] * kD), 3.0 * s[0] * kA, 1e-9);
  EXPECT_NEAR(MaxAdhesionForce(p, e[2] * kD), 3.0 * s[2] * kA, 1e-9);
  EXPECT_NEAR(MaxAdhesionForce(p, 0.5 * (e[1] + e[2]) * kD), 3.0 * 0.5 * (s[1] + s[2]) * kA, 1e-9);  // interpolated
  p.cohesion = false;
  EXPECT_EQ(MaxAdhesionForce(p, 0.02 * kD), 0.0);
}

TEST(SoilLaw, StickBelowAndSlipAboveMuTimesTheRepulsion) {
  const SoilParams p = Nominal();
  const Eigen::Vector3d n(0, 0, 1);
  const double f_rep = 10.0, mu = 0.1, k_t = 0.2857 * kKn, dt = 1e-4;
  TangentialHistory h;
  const Eigen::Vector3d v(1e-4, 0, 0);  // a tenth of the slip velocity: the Coulomb element's dashpot
  // the dashpot mu F / v_slip stepped backward for the mass it acts on (half the particle's, over
  // four sticking contacts): c / (1 + c dt / m)
  const double c = mu * f_rep / 1e-3, m = p.Mass() / 8.0, coulomb = c / (1.0 + c * dt / m) * v.x();
  Eigen::Vector3d f;
  for (int i = 0; i < 10; ++i) f = SoilContactLaw(p).Tangential(n, v, f_rep, dt, &h);
  // stick: anchor spring plus the Coulomb element, opposing the motion
  const double stick = k_t * 10 * 1e-4 * dt + coulomb;
  ASSERT_LT(stick, mu * f_rep);
  EXPECT_NEAR(f.x(), -stick, 1e-9);
  EXPECT_NEAR(f.y(), 0.0, 1e-12);
  // keep pushing: the force stops at mu F_repulsion and the anchor slides
  for (int i = 0; i < 1000; ++i) f = SoilContactLaw(p).Tangential(n, v, f_rep, dt, &h);
  EXPECT_NEAR(f.norm(), mu * f_rep, 1e-12);
  // stop: the spring keeps what it carried while sliding (mu F less the Coulomb element's share)
  f = SoilContactLaw(p).Tangential(n, Eigen::Vector3d::Zero(), f_rep, dt, &h);
  EXPECT_NEAR(f.x(), -(mu * f_rep - coulomb), 1e-9);
  // no repulsion (only adhesion): no friction
  EXPECT_EQ(SoilContactLaw(p).Tangential(n, v, 0.0, dt, &h).norm(), 0.0);
}

// The Coulomb element's dashpot is stepped backward: one step of a mass m sliding against it
// (v' = v - dt c' v / m) is implicit Euler's v / (1 + c dt / m), so it never reverses the sliding
// however stiff the dashpot is for the step; as dt -> 0 it is the paper's mu F / max(v_slip, |v|).
TEST(SoilLaw, TheCoulombDashpotIsSteppedBackwardAndTendsToThePapersAsTheStepShrinks) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    const double mu = 0.05 + u(rng), f = 1000.0 * u(rng), v_slip = 1e-3, speed = 2e-3 * u(rng);
    const double m = 1e-3 + u(rng), dt = std::pow(10.0, -7.0 + 4.0 * u(rng)), v = -speed;
    const double c = mu * f / std::max(v_slip, speed);
    const double ce = -AsperityFriction::CoulombDamping(mu, f, v_slip, speed, dt / m);
    const double stepped = v - dt * ce * v / m;
    EXPECT_NEAR(stepped, v / (1.0 + c * dt / m), 1e-12 * speed) << "c dt / m = " << c * dt / m;
    EXPECT_GE(stepped * v, 0.0);  // no reversal
    EXPECT_LE(ce, c);
    EXPECT_NEAR(ce, c, c * c * dt / m + 1e-12 * c);  // c - c' = c^2 dt / m / (1 + c dt / m)
  }
  // explicit (no mass given): the paper's element
  EXPECT_DOUBLE_EQ(-AsperityFriction::CoulombDamping(0.1, 300.0, 1e-3, 5e-4, 0.0), 0.1 * 300.0 / 1e-3);
}

TEST(SoilLaw, BadSoilFileNamesTheFileAndKey) {
  try {
    SoilParams::Read(YamlReader::FromString(
        "diameter: 0.03\ndensity: 1800\nstiffness_stress: 4.42e7\ndamping_area: 2.1e4\nseparation_factor: 0.1\n"
        "adhesion_depth: 0.01\nadhesion_peak: 0.02\nfriction: 0.1\ntangential_stiffness_ratio: 0.3\n"
        "slip_velocity: 1e-3\nviscosity: 0\ncohesion_factor: 1\nrelax_speed: 0.045\nplasticity: true\n"
        "cohesion: true\nplastic_strain_vs_stress: [[0, 0]]\nadhesion_stress_vs_plastic_strain: [[0, 500]]\n",
        "soils/bad.yaml"));
    FAIL() << "an adhesion peak beyond the adhesion depth was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("soils/bad.yaml: adhesion_peak"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dem_mobility::core
