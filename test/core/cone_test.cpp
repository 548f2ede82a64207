// The cone penetrometer and the compression test (issue 5): bad input refused with the key named;
// the calibration table; the PID holds the cone's speed; the cone index rises with f and lies in
// the band the calibration table predicts; the compression test compacts plastically.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/soil/calibration.h"
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
  EXPECT_NO_THROW(Cone({"fidelity=coarse", "cohesion_factor=40"}));
  ExpectRefused({"cohesion_factor=0.01"}, {"cohesion_factor", "outside the range a soil takes [0.05, 40]"});
  ExpectRefused({"cohesion_factor=41"}, {"cohesion_factor", "outside"});
  // a cone wider than the test level's 1 m container (with the length its 30 degrees need)
  ExpectRefused({"fidelity=test", "cone.base_diameter=1.1", "cone.length=2.05263"},
                {"cone.base_diameter", "wider than the container"});
  ExpectRefused({"cone.length=0.5"}, {"cone.length", "0.69"});
  ExpectRefused({"fidelity=finest"}, {"fidelity", "no level 'finest'", "coarse"});
  ExpectRefused({"levels.coarse.ci_window=[0.5, 0.8]"}, {"ci_window", "before the cone's base"});
  ExpectRefused({"levels.coarse.soil_depth=1.0"}, {"ci_window", "too deep"});
  ExpectRefused({"cone_index=1000"}, {"cone_index", "outside the calibrated range"});
  ExpectRefused({"pid.kp=-1"}, {"pid.kp"});
  ExpectRefused({"fidelity=coarse_cal", "levels.coarse_cal.approach_depth=0.8"},
                {"levels.coarse_cal.approach_depth", "above the CI window"});
  ExpectRefused({"levels.coarse.approach_speed=0.4"}, {"levels.coarse.approach_depth", "missing"});
  ExpectRefused({"time_step=0"}, {"time_step"});
}

// A run may take another step than its level's (a strong soil at the step the guard names): the
// rest of the level stays as it is.
TEST(ConeConfig, AStepGivenForTheRunTakesThePlaceOfTheLevels) {
  const ConeParams level = Cone({"fidelity=coarse_cal"});
  const ConeParams run = Cone({"fidelity=coarse_cal", "time_step=6e-5"});
  EXPECT_DOUBLE_EQ(level.level.time_step, 8e-5);
  EXPECT_DOUBLE_EQ(run.level.time_step, 6e-5);
  EXPECT_EQ(run.level.name, "coarse_cal");
  EXPECT_DOUBLE_EQ(run.level.particle_diameter, level.level.particle_diameter);
  EXPECT_DOUBLE_EQ(run.level.cone_speed, level.level.cone_speed);
}

TEST(ConeConfig, ConeIndexTurnsIntoFThroughTheTable) {
  // the scene names the directory; the table is the one of the level's particles and friction
  const ConeParams base = Cone({});
  const CiCalibration cal = CiCalibration::LoadFor(DM_CONFIG_DIR "/calibration", base.level.particle_diameter,
                                                   base.friction);
  const double ci = 0.5 * (cal.ci.front() + cal.ci.back());
  const ConeParams p = Cone({"cone_index=" + std::to_string(ci)});
  EXPECT_DOUBLE_EQ(p.strength.cohesion_factor, cal.CohesionFactor(ci));
  EXPECT_DOUBLE_EQ(p.soil.cohesion_factor, p.strength.cohesion_factor);
  EXPECT_DOUBLE_EQ(p.strength.requested_cone_index_psi, ci);
  ASSERT_TRUE(p.strength.calibration);
  EXPECT_EQ(p.strength.calibration->file, cal.file);
  // the result says which table it used, for which particles, and the table's error
  const std::string text = ConeResultFile(ConeResult(), p).Text();
  for (const char* key : {"calibration_table:", "calibration_level:", "calibration_particle_diameter:",
                          "calibration_error_vs_finest:"})
    EXPECT_NE(text.find(key), std::string::npos) << key << " not in:\n" << text;
  EXPECT_NE(text.find(cal.file), std::string::npos);
  // without cone_index no table is used, and the result names none
  EXPECT_FALSE(Cone({"cohesion_factor=2"}).strength.calibration);
}

// A level whose particles no table was made for: the cone index is refused, naming the key and
// both sizes (the level's and the tables').
TEST(ConeConfig, ConeIndexRefusedWithoutATableForTheLevelsParticles) {
  ExpectRefused({"fidelity=fine", "cone_index=100"}, {"cone_index", "particle_diameter", "0.04", "0.06"});
  ExpectRefused({"friction=0.3", "cone_index=100"}, {"cone_index", "friction 0.3", "mu 0.1"});
}

// A table as the sweep writes it, with what the test changes substituted.
std::string TableText(double d, double mu, const std::string& extra = "") {
  return "particle_diameter: " + std::to_string(d) + "\nfriction: " + std::to_string(mu) +
         "\nfidelity: coarse\ncubic: [0, 0, 0.1, -2]\nband: 0.02\n"
         "table: [[30, 1.0], [50, 3.0], [100, 8.0]]\n"
         "points: {f: [1.0, 3.0, 8.0], ci_mean: [30, 50, 100], ci_std: [1.0, 2.0, 3.0], seeds: [3, 3, 3]}\n"
         "runs: {f: [1, 1, 1], seed: [1, 2, 3], ci: [29, 30, 31]}\n"
         "provenance:\n  commit: abc1234\n  seeds: [1, 2, 3]\n  soil_file: config/soils/nominal_clay.yaml\n"
         "  soil_sha256: " + std::string(64, 'a') + "\n  scene_file: config/scenes/cone_penetrometer.yaml\n"
         "  date: '2026-11-29'\n  conditions: {container_diameter: 1.2, soil_depth: 1.6, cone_speed: 0.4, "
         "ci_window: [0.78, 0.92]}\n"
         "error_vs_finest: {level: medium, relative: 0.3, note: measured}\n" + extra;
}

std::string Without(std::string text, const std::string& line) {
  const size_t k = text.find(line);
  EXPECT_NE(k, std::string::npos) << line;
  return text.erase(k, text.find('\n', k) - k + 1);
}

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("dm_calibration_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string p = (path / name).string();
    std::ofstream(p) << text;
    return p;
  }
};

std::string Refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

void ExpectWords(const std::string& m, const std::vector<std::string>& words) {
  for (const std::string& w : words) EXPECT_NE(m.find(w), std::string::npos) << "'" << w << "' not in: " << m;
}

TEST(CiCalibration, InterpolatesBothWaysAndRefusesOutsideItsRange) {
  const CiCalibration c = CiCalibration::Read(YamlReader::FromString(TableText(0.06, 0.1), "cal.yaml"));
  EXPECT_DOUBLE_EQ(c.CohesionFactor(30), 1.0);
  EXPECT_DOUBLE_EQ(c.CohesionFactor(40), 2.0);
  EXPECT_DOUBLE_EQ(c.CohesionFactor(75), 5.5);
  EXPECT_DOUBLE_EQ(c.ConeIndex(5.5), 75.0);
  EXPECT_DOUBLE_EQ(c.ConeIndex(c.CohesionFactor(63.0)), 63.0);
  EXPECT_THROW(c.CohesionFactor(29.9), ConfigError);
  EXPECT_THROW(c.ConeIndex(8.5), ConfigError);
  std::string falling = TableText(0.06, 0.1);
  falling.replace(falling.find("[[30, 1.0], [50, 3.0]"), 21, "[[30, 3.0], [50, 1.0]");
  EXPECT_THROW(CiCalibration::Read(YamlReader::FromString(falling, "bad.yaml")), ConfigError);  // f falls with CI
}

TEST(CiCalibration, ReadsParticleSizePointsAndProvenance) {
  const CiCalibration c = CiCalibration::Read(YamlReader::FromString(TableText(0.06, 0.1), "cal.yaml"));
  EXPECT_DOUBLE_EQ(c.particle_diameter, 0.06);
  EXPECT_EQ(c.level, "coarse");
  ASSERT_EQ(c.points.size(), 3u);
  EXPECT_DOUBLE_EQ(c.points[1].ci_mean, 50.0);
  EXPECT_DOUBLE_EQ(c.points[1].ci_std, 2.0);
  EXPECT_EQ(c.MinSeeds(), 3);
  EXPECT_EQ(c.seeds, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(c.error_vs_finest.level, "medium");
  EXPECT_DOUBLE_EQ(c.error_vs_finest.relative, 0.3);
  bool commit = false, sha = false, speed = false;
  for (const auto& [k, v] : c.provenance) {
    commit = commit || (k == "commit" && v == "abc1234");
    sha = sha || (k == "soil_sha256" && v == std::string(64, 'a'));
    speed = speed || (k == "conditions.cone_speed" && v == "0.4");
  }
  EXPECT_TRUE(commit && sha && speed);
}

// Nothing loads a table that does not say which particles it holds for, or where it came from.
TEST(CiCalibration, RefusesATableWithoutParticleSizeProvenanceOrError) {
  const std::string good = TableText(0.06, 0.1);
  auto refused = [](const std::string& text, const std::vector<std::string>& words) {
    ExpectWords(Refusal([&] { CiCalibration::Read(YamlReader::FromString(text, "table.yaml")); }),
                std::vector<std::string>{"table.yaml"});
    ExpectWords(Refusal([&] { CiCalibration::Read(YamlReader::FromString(text, "table.yaml")); }), words);
  };
  refused(Without(good, "particle_diameter:"), {"particle_diameter", "missing"});
  std::string no_prov = good.substr(0, good.find("provenance:")) + good.substr(good.find("error_vs_finest:"));
  refused(no_prov, {"provenance", "missing"});
  refused(Without(good, "  soil_sha256:"), {"provenance.soil_sha256"});
  refused(Without(good, "  commit:"), {"provenance.commit"});
  std::string short_sha = good;
  short_sha.replace(short_sha.find(std::string(64, 'a')), 64, "abc");
  refused(short_sha, {"provenance.soil_sha256", "64 hex"});
  refused(Without(good, "points:"), {"points", "missing"});
  refused(Without(good, "error_vs_finest:"), {"error_vs_finest", "missing"});
  refused(good + "particle_size: 0.06\n", {"unknown key", "particle_size"});
  // an unknown error must say why
  std::string unknown = good;
  unknown.replace(unknown.find("{level: medium, relative: 0.3, note: measured}"), 46, "{level: coarse}");
  refused(unknown, {"error_vs_finest.relative"});
  // more seeds behind a point than the provenance lists
  std::string seeds = good;
  seeds.replace(seeds.find("seeds: [3, 3, 3]"), 16, "seeds: [3, 4, 3]");
  refused(seeds, {"points.seeds", "provenance.seeds"});
}

// One file made for another particle size is refused, naming both sizes.
TEST(CiCalibration, RefusesATableForAnotherParticleSize) {
  TempDir dir;
  const std::string file = dir.Write("cone_index_mu0.1_d0.05.yaml", TableText(0.05, 0.1));
  EXPECT_DOUBLE_EQ(CiCalibration::LoadFor(file, 0.05, 0.1).particle_diameter, 0.05);
  EXPECT_DOUBLE_EQ(CiCalibration::LoadFor(file, 0.05 * (1 + 1e-8), 0.1).particle_diameter, 0.05);
  ExpectWords(Refusal([&] { CiCalibration::LoadFor(file, 0.06, 0.1); }),
              {file, "particle_diameter", "0.05 m", "0.06 m"});
  ExpectWords(Refusal([&] { CiCalibration::LoadFor(file, 0.05, 0.05); }), {file, "friction", "0.1", "0.05"});
  ExpectWords(Refusal([&] { CiCalibration::LoadFor((dir.path / "none.yaml").string(), 0.05, 0.1); }),
              {"none.yaml"});
}

// From a directory, the table of the particles and friction asked for; none or two is an error
// that lists the tables there.
TEST(CiCalibration, LoadForPicksTheTableOfTheParticlesFromADirectory) {
  TempDir dir;
  dir.Write("a.yaml", TableText(0.05, 0.1));
  dir.Write("b.yaml", TableText(0.06, 0.1, "method: the one\n"));
  dir.Write("c.yaml", TableText(0.06, 0.05));
  dir.Write("notes.txt", "not a table");
  const std::string d = dir.path.string();
  const CiCalibration b = CiCalibration::LoadFor(d, 0.06, 0.1);
  EXPECT_EQ(b.file, (dir.path / "b.yaml").string());
  EXPECT_EQ(CiCalibration::LoadFor(d, 0.05, 0.1).file, (dir.path / "a.yaml").string());
  EXPECT_EQ(CiCalibration::LoadFor(d, 0.06, 0.05).file, (dir.path / "c.yaml").string());
  ExpectWords(Refusal([&] { CiCalibration::LoadFor(d, 0.04, 0.1); }),
              {d, "particle_diameter", "0.04", "a.yaml (0.05 m, mu 0.1)", "b.yaml (0.06 m, mu 0.1)",
               "c.yaml (0.06 m, mu 0.05)"});
  dir.Write("d.yaml", TableText(0.06, 0.1));
  ExpectWords(Refusal([&] { CiCalibration::LoadFor(d, 0.06, 0.1); }), {d, "b.yaml", "d.yaml", "one per"});
  // a table in the directory without a particle size is an error, not skipped
  dir.Write("d.yaml", Without(TableText(0.03, 0.1), "particle_diameter:"));
  ExpectWords(Refusal([&] { CiCalibration::LoadFor(d, 0.06, 0.1); }), {"d.yaml", "particle_diameter"});
}

TEST(CiCalibration, DescribeWritesTheTableIntoAResult) {
  const CiCalibration c = CiCalibration::Read(YamlReader::FromString(TableText(0.06, 0.1), "cal.yaml"));
  ResultFile r("scene.yaml", "wheel");
  c.Describe(&r);
  const YAML::Node n = YAML::Load(r.Text());
  EXPECT_EQ(n["calibration_table"].as<std::string>(), "cal.yaml");
  EXPECT_EQ(n["calibration_level"].as<std::string>(), "coarse");
  EXPECT_DOUBLE_EQ(n["calibration_particle_diameter"].as<double>(), 0.06);
  EXPECT_DOUBLE_EQ(n["calibration_error_vs_finest"].as<double>(), 0.3);
  EXPECT_EQ(n["calibration_finest_level"].as<std::string>(), "medium");
  EXPECT_EQ(n["calibration_seeds"].as<int>(), 3);
  // the scatter: the band, and the worst point over its seeds (stds 1, 2, 3 of means 30, 50, 100)
  EXPECT_DOUBLE_EQ(n["calibration_band"].as<double>(), 0.02);
  EXPECT_DOUBLE_EQ(n["calibration_points_relative_std_max"].as<double>(), 2.0 / 50.0);
  // no finer level run: a text that says why, never NaN
  std::string one = TableText(0.06, 0.1);
  one.replace(one.find("{level: medium, relative: 0.3, note: measured}"), 46,
              "{level: coarse, note: only this level was run}");
  ResultFile r2("scene.yaml", "wheel");
  CiCalibration::Read(YamlReader::FromString(one, "cal.yaml")).Describe(&r2);
  const std::string e = YAML::Load(r2.Text())["calibration_error_vs_finest"].as<std::string>();
  EXPECT_NE(e.find("only this level was run"), std::string::npos) << e;
  // one seed per point: no spread over seeds, said in words
  std::string single = TableText(0.06, 0.1);
  single.replace(single.find("seeds: [3, 3, 3]"), 16, "seeds: [1, 1, 1]");
  single.replace(single.find("ci_std: [1.0, 2.0, 3.0], "), 25, "");
  ResultFile r3("scene.yaml", "wheel");
  CiCalibration::Read(YamlReader::FromString(single, "cal.yaml")).Describe(&r3);
  const std::string w = YAML::Load(r3.Text())["calibration_points_relative_std_max"].as<std::string>();
  EXPECT_NE(w.find("no point of the table has more than one seed"), std::string::npos) << w;
}

// Every table installed in config/calibration says which particles it holds for, and one table
// holds per particle size and friction.
TEST(CiCalibration, InstalledTablesCarryTheirParticleSize) {
  int tables = 0;
  for (const auto& e : std::filesystem::directory_iterator(DM_CONFIG_DIR "/calibration")) {
    if (e.path().extension() != ".yaml") continue;
    ++tables;
    const CiCalibration c = CiCalibration::Load(e.path().string());
    EXPECT_GT(c.particle_diameter, 0.0) << c.file;
    EXPECT_FALSE(c.provenance.empty()) << c.file;
    EXPECT_EQ(CiCalibration::LoadFor(DM_CONFIG_DIR "/calibration", c.particle_diameter, c.friction).file,
              CiCalibration::LoadFor(c.file, c.particle_diameter, c.friction).file);
  }
  EXPECT_GT(tables, 0);
}

// Every installed table is measured over table 3's strong end the way the issue of the tables asks:
// at least 7 f values, 3 seeds at each (the paper size: 3 seeds at two f, one elsewhere), the mean CI
// rising with f at every point, and a measured point at or above table 3's 242 psi. (The weak end,
// a point at or below 30 psi, is not met at 0.06 m: docs/cone-penetrometer.md.)
TEST(CiCalibration, InstalledTablesRiseWithFAndReachTable3sStrongestSoil) {
  for (const auto& e : std::filesystem::directory_iterator(DM_CONFIG_DIR "/calibration")) {
    if (e.path().extension() != ".yaml") continue;
    const CiCalibration c = CiCalibration::Load(e.path().string());
    ASSERT_GE(c.points.size(), 7u) << c.file;
    int three = 0;
    for (size_t k = 0; k < c.points.size(); ++k) {
      if (c.points[k].seeds >= 3) ++three;
      if (k == 0) continue;
      EXPECT_GT(c.points[k].f, c.points[k - 1].f) << c.file;
      EXPECT_GT(c.points[k].ci_mean, c.points[k - 1].ci_mean) << c.file << ", f = " << c.points[k].f;
    }
    if (c.level == "paper_cal")
      EXPECT_GE(three, 2) << c.file;
    else
      EXPECT_EQ(three, static_cast<int>(c.points.size())) << c.file;
    EXPECT_GE(c.points.back().ci_mean, 242.0) << c.file;
  }
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

// The cone index rises with f, and a run with a seed that is in none of the table's runs lies
// within the band the calibration table of the tiny particles (0.1 m, config/calibration/, from
// the sweep at the table's own level, tiny_cal) predicts for its f, at two of the table's f values:
// a validation of the table, not a repeat of a run behind it. In both runs the PID holds the cone
// at its 0.1 m/s past the approach, the lid held the consolidation pressure, and the soil
// compacted under it. (The 0.1 m table's two runs take about 85 s on two threads; the 0.06 m
// table's took 263 s each.)
TEST(ConePenetrometer, ConeIndexRisesWithFWithinTheCalibrationBand) {
  const CiCalibration cal = CiCalibration::LoadFor(DM_CONFIG_DIR "/calibration", 0.1, 0.1);
  const ConeParams level = Cone({"fidelity=" + cal.level});
  ASSERT_DOUBLE_EQ(level.level.particle_diameter, cal.particle_diameter);
  EXPECT_GE(cal.MinSeeds(), 3);  // every point of the table is a mean over seeds
  ASSERT_GE(cal.points.size(), 3u);
  // two of the cohesion factors the sweep ran, the table's second and fourth (0.2 and 1: far
  // enough apart that one run's rise stands clear of the window's scatter, where the second and
  // third, 0.2 and 0.5, rose 17.6 psi against a scatter of 9.6 psi each; and weak enough for the
  // PID to hold the cone within 5 %, which at the fifth, 1.5, strays 5.3-6.7 %):
  // docs/cone-penetrometer.md
  ASSERT_GE(cal.points.size(), 4u);
  const double fs[2] = {cal.points[1].f, cal.points[3].f};
  ASSERT_FALSE(cal.seeds.empty());
  const int seed = *std::max_element(cal.seeds.begin(), cal.seeds.end()) + 1;  // in none of the table's runs
  ConeResult r[2];
  std::thread runs[2];
  for (int k = 0; k < 2; ++k)
    runs[k] = std::thread([&, k] {
      r[k] = ConePenetrometer(Cone({"fidelity=" + cal.level, "friction=0.1", "threads=1", "seed=" + std::to_string(seed),
                                    "cohesion_factor=" + std::to_string(fs[k])}))
                 .Run();
    });
  for (auto& t : runs) t.join();
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(r[k].error.empty()) << r[k].error;
    const double predicted = cal.ConeIndex(fs[k]);
    std::printf("f = %g, seed %d: CI %.2f psi, the table's %.2f psi (band %.1f %%)\n", fs[k], seed, r[k].cone_index_psi,
                predicted, 100.0 * cal.band);
    EXPECT_NEAR(r[k].cone_index_psi, predicted, std::max(2.0 * cal.band, 0.05) * predicted) << "f = " << fs[k];
    // the PID: every 10 ms sample past the approach (0.4 m/s down to approach_depth, then 0.1 m/s,
    // from a particle diameter further on) within 5 % of the cone's speed
    ASSERT_DOUBLE_EQ(level.level.cone_speed, 0.1);
    ASSERT_GT(level.level.approach_speed, 0.0);
    int held = 0;
    for (const ConeSample& c : r[k].samples) {
      if (c.depth < level.level.approach_depth + level.level.particle_diameter) continue;
      ++held;
      EXPECT_NEAR(c.speed, 0.1, 0.005) << "f = " << fs[k] << ", at a tip depth of " << c.depth << " m";
    }
    EXPECT_GT(held, 50) << "f = " << fs[k];
    // the lid held (close to) the consolidation pressure; the soil compacted under it
    EXPECT_NEAR(r[k].lid_pressure_reached, 33.3e3, 0.1 * 33.3e3) << "f = " << fs[k];
    EXPECT_GT(r[k].density_consolidated, r[k].density_poured) << "f = " << fs[k];
  }
  EXPECT_GT(r[1].cone_index_psi - r[0].cone_index_psi, 2.0 * (r[0].cone_index_std_psi + r[1].cone_index_std_psi));
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
