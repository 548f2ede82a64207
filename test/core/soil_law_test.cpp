// The cohesive soil particle law (paper section 2.3) against the formulas of the paper and table 2.
#include <gtest/gtest.h>

#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
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

TEST(SoilLaw, PlasticDeformationGrowsAlongFig8AndStaysAfterUnloading) {
  const SoilParams p = Nominal();
  double delta = 0.0;
  // loading: at compressive stress s the deformation is the table's strain times d
  const double stresses[] = {5.0e3, 2.0e4, 3.5e4, 1.0e5};
  const double strains[] = {0.004, 0.012, 0.017, 0.030};  // 3.5e4: halfway between 0.012 and 0.022
  for (int i = 0; i < 4; ++i) {
    delta = UpdatePlasticDeformation(p, delta, stresses[i] * kA, 0.0, 1e-5);
    EXPECT_NEAR(delta, strains[i] * kD, 1e-12) << stresses[i];
  }
  // partial unloading to 5e3 Pa (below the 1e5 Pa reached), pressed at least as hard as its
  // contacts pull on it: the deformation stays, even where the pull reaches the particle's
  // full adhesion (eq. 16 relaxes only under tension or without compression)
  const double f_adh = MaxAdhesionForce(p, delta);
  ASSERT_GT(f_adh, 5.0e3 * kA);
  for (int i = 0; i < 1000; ++i) delta = UpdatePlasticDeformation(p, delta, 5.0e3 * kA, 5.0e3 * kA, 1e-5);
  EXPECT_NEAR(delta, 0.030 * kD, 1e-12);
  for (int i = 0; i < 1000; ++i) delta = UpdatePlasticDeformation(p, delta, f_adh, f_adh, 1e-5);
  EXPECT_NEAR(delta, 0.030 * kD, 1e-12);
}

TEST(SoilLaw, RelaxationUnderTensionStopsAtFig8ForThePresentLoad) {
  const SoilParams p = Nominal();
  double delta = 0.030 * kD;
  const double dt = 1e-5;
  // compressed at 5e3 Pa but pulled harder by an adhesive contact: relaxes at V_relax ...
  const double pull = 1.5 * 5.0e3 * kA;
  for (int i = 0; i < 100; ++i) delta = UpdatePlasticDeformation(p, delta, 5.0e3 * kA, pull, dt);
  EXPECT_NEAR(delta, 0.030 * kD - 100 * 0.045 * dt, 1e-12);
  // ... down to fig. 8's strain at 5e3 Pa (0.004), where it stops
  for (int i = 0; i < 100000; ++i) delta = UpdatePlasticDeformation(p, delta, 5.0e3 * kA, pull, dt);
  EXPECT_NEAR(delta, 0.004 * kD, 1e-12);
}

TEST(SoilLaw, RelaxationAtVrelaxFlooredAtZero) {
  const SoilParams p = Nominal();
  double delta = 0.030 * kD;
  const double dt = 1e-5;
  // released (no compression, no contact): eq. 16 removes V_relax dt each step
  for (int i = 0; i < 100; ++i) delta = UpdatePlasticDeformation(p, delta, 0.0, 0.0, dt);
  EXPECT_NEAR(delta, 0.030 * kD - 100 * 0.045 * dt, 1e-12);
  // until nothing is left, and no further
  for (int i = 0; i < 10000; ++i) delta = UpdatePlasticDeformation(p, delta, 0.0, 0.0, dt);
  EXPECT_EQ(delta, 0.0);
  // plasticity off: nothing changes
  SoilParams off = p;
  off.plasticity = false;
  EXPECT_EQ(UpdatePlasticDeformation(off, 0.001, 0.0, 100.0, dt), 0.001);
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
  const Eigen::Vector3d v(1e-4, 0, 0);  // a tenth of the slip velocity: the Coulomb element gives 0.1 mu F
  Eigen::Vector3d f;
  for (int i = 0; i < 10; ++i) f = SoilContactLaw(p).Tangential(n, v, f_rep, dt, &h);
  // stick: anchor spring plus the Coulomb element, opposing the motion
  const double stick = k_t * 10 * 1e-4 * dt + 0.1 * mu * f_rep;
  ASSERT_LT(stick, mu * f_rep);
  EXPECT_NEAR(f.x(), -stick, 1e-9);
  EXPECT_NEAR(f.y(), 0.0, 1e-12);
  // keep pushing: the force stops at mu F_repulsion and the anchor slides
  for (int i = 0; i < 1000; ++i) f = SoilContactLaw(p).Tangential(n, v, f_rep, dt, &h);
  EXPECT_NEAR(f.norm(), mu * f_rep, 1e-12);
  // stop: the spring keeps what it carried while sliding (mu F less the Coulomb element's share)
  f = SoilContactLaw(p).Tangential(n, Eigen::Vector3d::Zero(), f_rep, dt, &h);
  EXPECT_NEAR(f.x(), -(mu * f_rep - 0.1 * mu * f_rep), 1e-9);
  // no repulsion (only adhesion): no friction
  EXPECT_EQ(SoilContactLaw(p).Tangential(n, v, 0.0, dt, &h).norm(), 0.0);
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
