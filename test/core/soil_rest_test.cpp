// A consolidated bed comes to rest (issue 49; docs/soil-model.md, "Reading of eq. 16"): the soil
// law's plastic changes do no net work on it. Beds of the coarse level's 0.06 m particles are
// poured, pressed by a lid at the paper's 33.3 kPa and released, at cohesion factors from the least
// to the largest the tables use (read from config/calibration: the test follows the tables):
//  - with V_relax = 0.045 m/s throughout, the plastic changes take energy out of the released bed
//    (the DEM's plastic ledger over the release is not positive) and, up to the paper's largest f
//    (12), never pour it in at more than 10 % of the bed's weight times V_relax over 10 ms (the old
//    reading poured 40 times that scale: 0.28 MW into the tiny soil patch);
//  - the cone's container (as the tiny table is made in it) comes to rest (median particle speed
//    below 1e-3 m/s) within a second of the release and stays at rest at the paper's largest f
//    (12) and at the largest f the tables use.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/dem/dem_watchdogs.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/soil/soil_strength.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

constexpr double kD = 0.06, kDt = 8e-5;  // the coarse level's particles and step
constexpr double kVrelax = 0.045;        // table 2

struct Bed {
  std::unique_ptr<DemSystem> dem;
  RestWatch release;
  double weight = 0.0;  // [N]
};

// A cylinder 0.6 m across, 700 particles poured, pressed at 33.3 kPa for 0.2 s and released for
// `release` s with V_relax = `relax`.
Bed Prepare(double f, double relax, double release) {
  SoilParams p = Nominal();
  p.diameter = kD;
  p.cohesion_factor = f;
  p.relax_speed = relax;
  DemSettings st;
  st.max_overlap = 0.4;  // as the cone's scene: the lid's pressure on strong soil
  Bed b;
  b.dem = std::make_unique<DemSystem>(p, st);
  const double R = 0.3;
  const CylinderBed bed = AddCylinderBed(b.dem.get(), R, 700, 16, 1);
  // the level's step, or (a large f, as the table runs it) 0.9 of the step the guard allows
  b.dem->Finalize(std::min(kDt, 0.9 * DemCriticalTimeStep(p, p.Mass(), 12).dt_crit));
  SoilPreparationParams prep;
  prep.settle_time = 0.4;
  prep.hold_time = 0.2;
  prep.lid_speed = 0.5;
  prep.release_time = release;
  SoilPreparation sp(b.dem.get(), bed.lid, M_PI * R * R, bed.wall_height + 1.0, prep, "rest test");
  while (!sp.done()) sp.Step();
  b.release = sp.rest();
  b.weight = b.dem->num_alive() * b.dem->mass() * 9.81;
  return b;
}

// The largest f of the table at this particle size and mu 0.1.
double LargestTableF(double diameter) {
  const CiCalibration t = CiCalibration::LoadFor(DM_CONFIG_DIR "/calibration", diameter, 0.1);
  double f = 0.0;
  for (const CiCalibration::Point& q : t.points) f = std::max(f, q.f);
  return f;
}

TEST(SoilAtRest, PlasticChangesTakeEnergyOutOfAReleasedBedAtEveryCohesion) {
  // (the table is read inside the test: a missing table fails it, not the program's start)
  for (const double f : {SoilStrength::kMinCohesionFactor, 1.0, 5.0, 12.0, LargestTableF(kD)}) {
    const Bed b = Prepare(f, kVrelax, 1.0);
    const RestWatch& w = b.release;
    std::printf("f = %5.2f: over the 1 s release the plastic changes moved %.3g J (largest power %.3g W; weight x "
                "V_relax %.3g W); median speed at its end %.3g m/s\n",
                f, w.plastic, w.plastic_max_power, b.weight * kVrelax, w.median_speed);
    EXPECT_GE(w.watched, 0.99) << "f " << f;
    EXPECT_LE(w.plastic, 0.0) << "f " << f;
    // (at some instants the changes of neighbours in the same step, beyond the first-order terms
    // each particle's bound covers, move a little energy in: up to the paper's largest f, 0-6.4 %
    // of this scale over 10 ms, the most at f = 10 while the released bed slumps (6 J of kinetic
    // energy; the next 10 ms take 0.5 J out). The old reading poured in 40 times the scale (0.28 MW
    // into the tiny soil patch): 10 % tells the two apart. Above f = 12 they move more at instants
    // (133 W at f = 30, twice the scale), though never net: a measured not-met of issue 49,
    // docs/soil-model.md)
    if (f <= 12.0) {
      EXPECT_LE(w.plastic_max_power, 0.10 * b.weight * kVrelax) << "f " << f;
    }
  }
}

// 5 % of the container bed's weight times V_relax [W]: the most the plastic changes may pour in
double PowerBound(const ConeParams& p, int particles) {
  return 0.05 * particles * p.soil.Mass() * 9.81 * p.soil.relax_speed;
}

// The cone's container of the tiny table's level (tiny_cal: the paper's 2 m, 0.1 m particles poured
// 1.8 m deep, some 6,300), released for 1 s: its rest watch, and the power bound of its bed.
struct Released {
  RestWatch w;
  double power_bound = 0.0;  // [W]
};
Released ReleasedContainer(double f) {
  const ConeParams p = ConeParams::Read(YamlReader::LoadWithOverrides(
      DM_CONFIG_DIR "/scenes/cone_penetrometer.yaml",
      {"fidelity=tiny_cal", "cohesion_factor=" + std::to_string(f), "lid.release_time=1.0", "threads=2"}));
  ConePenetrometer cone(p);
  while (!cone.penetrating()) cone.Step();
  const ConeResult r = cone.Result();
  const RestWatch& w = r.rest;
  std::printf("the cone's container, f = %.1f, %d particles: at rest (median below %.0e m/s) from %.2f s; median "
              "%.3g m/s after %.2f s; plastic changes %.3g J (largest power %.3g W, bound %.3g W)\n",
              r.cohesion_factor, r.particles, RestWatch::kRestSpeed, w.time_to_rest, w.median_speed, w.watched,
              w.plastic, w.plastic_max_power, PowerBound(p, r.particles));
  EXPECT_GE(w.watched, 0.99);
  return {w, PowerBound(p, r.particles)};
}

// At the paper's largest f (12) the container comes to rest within the second and stays at rest
// (its median particle speed below 1e-3 m/s at the end too), and the plastic changes take energy
// out, never pouring it in at more than 5 % of the bed's weight times V_relax (the coarse level's
// 1.2 m container, 9,280 particles, does the same: docs/soil-model.md).
TEST(SoilAtRest, TheConesContainerComesToRestWithinASecondAtThePapersLargestCohesion) {
  const Released c = ReleasedContainer(12.0);
  const RestWatch& w = c.w;
  EXPECT_GE(w.time_to_rest, 0.0) << "not at rest within the second";
  EXPECT_LT(w.median_speed, RestWatch::kRestSpeed);
  EXPECT_LE(w.plastic, 0.0);
  EXPECT_LE(w.plastic_max_power, c.power_bound);
}

// At the largest f the tables use (7 at 0.1 m, with the Coulomb dashpot stepped backward) the
// container comes to rest within the second and stays at rest, and the plastic changes take energy
// out, never pouring it in at more than 5 % of the bed's weight times V_relax (with the explicit
// dashpot the table ran to f = 24, where the bed fell below the rest speed but moved again).
TEST(SoilAtRest, AtTheLargestCohesionTheTablesUseTheConesContainerComesToRestWithinASecondAndStays) {
  const Released c = ReleasedContainer(LargestTableF(0.1));
  const RestWatch& w = c.w;
  EXPECT_GE(w.time_to_rest, 0.0) << "not at rest within the second";
  EXPECT_LT(w.time_to_rest, 1.0);
  EXPECT_LT(w.median_speed, RestWatch::kRestSpeed);
  EXPECT_LE(w.plastic, 0.0);
  EXPECT_LE(w.plastic_max_power, c.power_bound);
}

}  // namespace
}  // namespace dem_mobility::core
