// The cone penetrometer and the compression test (issue 5): bad input refused with the key named;
// the calibration table; the PID holds the cone's speed; the cone index rises with f and lies in
// the band the calibration table predicts; the compression test compacts plastically.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/scenes/calibration.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/uniaxial_compression.h"

namespace dem_mobility::core {
namespace {

const char* kScene = DM_CONFIG_DIR "/scenes/cone_penetrometer.yaml";

ConeParams Cone(const std::vector<std::string>& overrides) {
  return ConeParams::Read(YamlReader::LoadWithOverrides(kScene, overrides));
}

void ExpectRefused(const std::vector<std::string>& overrides, const std::vector<std::string>& words) {
  try {
    Cone(overrides);
    ADD_FAILURE() << "accepted: " << ::testing::PrintToString(overrides);
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cone_penetrometer.yaml"), std::string::npos) << m;  // the file is named
    for (const std::string& w : words) EXPECT_NE(m.find(w), std::string::npos) << "'" << w << "' not in: " << m;
  }
}

TEST(ConeConfig, RefusesBadInputNamingTheKey) {
  EXPECT_NO_THROW(Cone({"fidelity=coarse", "cohesion_factor=12"}));
  ExpectRefused({"cohesion_factor=0.01"}, {"cohesion_factor", "outside the paper's range [0.05, 12]"});
  ExpectRefused({"cohesion_factor=13"}, {"cohesion_factor", "outside"});
  // a cone wider than the test level's 1 m container (with the length its 30 degrees need)
  ExpectRefused({"fidelity=test", "cone.base_diameter=1.1", "cone.length=2.05263"},
                {"cone.base_diameter", "wider than the container"});
  ExpectRefused({"cone.length=0.5"}, {"cone.length", "0.69"});
  ExpectRefused({"fidelity=finest"}, {"fidelity", "no level 'finest'", "coarse"});
  ExpectRefused({"levels.coarse.ci_window=[0.5, 0.8]"}, {"ci_window", "before the cone's base"});
  ExpectRefused({"levels.coarse.soil_depth=1.0"}, {"ci_window", "too deep"});
  ExpectRefused({"cone_index=1000"}, {"cone_index", "outside the calibrated range"});
  ExpectRefused({"pid.kp=-1"}, {"pid.kp"});
}

TEST(ConeConfig, ConeIndexTurnsIntoFThroughTheTable) {
  const CiCalibration cal = CiCalibration::Load(DM_CONFIG_DIR "/calibration/cone_index_mu0.1.yaml");
  const double ci = 0.5 * (cal.ci.front() + cal.ci.back());
  const ConeParams p = Cone({"cone_index=" + std::to_string(ci)});
  EXPECT_DOUBLE_EQ(p.cohesion_factor, cal.CohesionFactor(ci));
  EXPECT_DOUBLE_EQ(p.soil.cohesion_factor, p.cohesion_factor);
  EXPECT_DOUBLE_EQ(p.requested_ci, ci);
}

TEST(CiCalibration, InterpolatesBothWaysAndRefusesOutsideItsRange) {
  const CiCalibration c = CiCalibration::Read(YamlReader::FromString(
      "friction: 0.1\ncubic: [0, 0, 0.1, -2]\ntable: [[30, 1.0], [50, 3.0], [100, 8.0]]\n", "cal.yaml"));
  EXPECT_DOUBLE_EQ(c.CohesionFactor(30), 1.0);
  EXPECT_DOUBLE_EQ(c.CohesionFactor(40), 2.0);
  EXPECT_DOUBLE_EQ(c.CohesionFactor(75), 5.5);
  EXPECT_DOUBLE_EQ(c.ConeIndex(5.5), 75.0);
  EXPECT_DOUBLE_EQ(c.ConeIndex(c.CohesionFactor(63.0)), 63.0);
  EXPECT_THROW(c.CohesionFactor(29.9), ConfigError);
  EXPECT_THROW(c.ConeIndex(8.5), ConfigError);
  EXPECT_THROW(CiCalibration::Read(YamlReader::FromString(
                   "friction: 0.1\ncubic: [0, 0, 0, 1]\ntable: [[30, 3.0], [50, 1.0]]\n", "bad.yaml")),
               ConfigError);  // f falling with CI
}

TEST(DemShapes, ContainerFacetsAndConeMatchTheirGeometry) {
  const double R = 0.6, L = 0.7, rb = 0.1875;
  for (const DemWall& w : MakeCylinderSideWalls("c", R, 1.0, 24)) {
    // each facet's plane lies at the inscribed radius
    const Eigen::Vector3d a = w.mesh.vertices[0], b = w.mesh.vertices[1];
    const Eigen::Vector3d mid = 0.5 * (a + b);
    EXPECT_NEAR(std::hypot(mid.x(), mid.y()), R, 1e-12);
  }
  const DemWall cone = MakeConeWall("cone", rb, L, 24);
  for (const Eigen::Vector3d& v : cone.mesh.vertices) {
    if (v.z() <= 0.0 || std::hypot(v.x(), v.y()) < 1e-12) continue;
    // the mantle's edge: a 30-degree cone (half angle 15 degrees)
    EXPECT_NEAR(std::hypot(v.x(), v.y()) / v.z(), std::tan(15.0 * M_PI / 180.0), 1e-3);
  }
}

// The PID holds the cone at 0.1 m/s once it is in the soil (a small, coarse scene).
TEST(ConePenetrometer, PidHoldsTheConeSpeedInTheSoil) {
  const ConeParams p = Cone({"fidelity=test", "cohesion_factor=2", "threads=1"});
  ASSERT_DOUBLE_EQ(p.level.cone_speed, 0.1);
  ConePenetrometer scene(p);
  const ConeResult r = scene.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  int in_soil = 0;
  for (const ConeSample& c : r.samples) {
    if (c.depth < p.level.particle_diameter) continue;
    ++in_soil;
    EXPECT_NEAR(c.speed, 0.1, 0.005) << "at a tip depth of " << c.depth << " m";
  }
  EXPECT_GT(in_soil, 50);
  EXPECT_GT(r.ci_psi, 0.0);
  // the lid held (close to) the consolidation pressure; the soil compacted under it
  EXPECT_NEAR(r.lid_pressure_reached, 33.3e3, 0.1 * 33.3e3);
  EXPECT_GT(r.density_consolidated, r.density_poured);
}

// The cone index rises with f, and each run lies within the band the calibration table
// (config/calibration/, from the coarse sweep) predicts for its f.
TEST(ConePenetrometer, ConeIndexRisesWithFWithinTheCalibrationBand) {
  const CiCalibration cal = CiCalibration::Load(DM_CONFIG_DIR "/calibration/cone_index_mu0.1.yaml");
  ASSERT_EQ(cal.level, "coarse");
  const double fs[2] = {0.3, 5.0};
  ConeResult r[2];
  std::thread runs[2];
  for (int k = 0; k < 2; ++k)
    runs[k] = std::thread([&, k] {
      r[k] = ConePenetrometer(Cone({"fidelity=coarse", "friction=0.1", "threads=1",
                                    "cohesion_factor=" + std::to_string(fs[k])}))
                 .Run();
    });
  for (auto& t : runs) t.join();
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(r[k].error.empty()) << r[k].error;
    const double predicted = cal.ConeIndex(fs[k]);
    EXPECT_NEAR(r[k].ci_psi, predicted, std::max(2.0 * cal.band, 0.05) * predicted) << "f = " << fs[k];
  }
  EXPECT_GT(r[1].ci_psi - r[0].ci_psi, 2.0 * (r[0].ci_std_psi + r[1].ci_std_psi));
}

// Piston-cylinder compression (fig. 9): the bulk density rises with the pressure, and most of the
// compaction stays when the pressure is taken off (plastic).
TEST(UniaxialCompression, DensityRisesWithPressureAndMostCompactionRemains) {
  const CompressionParams p = CompressionParams::Read(YamlReader::LoadWithOverrides(
      DM_CONFIG_DIR "/scenes/uniaxial_compression.yaml",
      {"loading=[1.0e4, 3.0e4, 1.0e5]", "unloading=[1.0e4]", "threads=2", "soil_depth=0.12",
       "cylinder_diameter=0.24"}));
  const CompressionResult r = RunUniaxialCompression(p);
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.loading.size(), 3u);
  double prev = r.density_poured;
  for (size_t k = 0; k < r.loading.size(); ++k) {
    // the piston is a proportional controller: while the soil creeps it lags by up to ~15 %
    EXPECT_NEAR(r.loading[k].pressure, p.loading[k], 0.2 * p.loading[k]);
    if (k > 0) {
      EXPECT_GT(r.loading[k].pressure, r.loading[k - 1].pressure);
    }
    EXPECT_GT(r.loading[k].density, prev) << "at " << r.loading[k].pressure << " Pa";
    prev = r.loading[k].density;
  }
  const double gained = r.loading.back().density - r.density_poured;
  EXPECT_GT(r.unloading.back().density - r.density_poured, 0.5 * gained);
  EXPECT_GT(r.density_released - r.density_poured, 0.5 * gained);
}

}  // namespace
}  // namespace dem_mobility::core
