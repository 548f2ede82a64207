// Bad input gives an error naming the file, the key path and the value.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_result.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/single_wheel.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "fuzz_targets.h"

namespace dem_mobility::core {
namespace {

namespace fs = std::filesystem;

// A scratch copy of the HMMWV folder in which one file is edited.
class VehicleCopy {
 public:
  VehicleCopy() {
    dir_ = fs::temp_directory_path() / ("dm_cfg_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    fs::remove_all(dir_);
    fs::copy(DM_CONFIG_DIR "/vehicles/hmmwv", dir_, fs::copy_options::recursive);
  }
  ~VehicleCopy() { fs::remove_all(dir_); }
  void Edit(const std::string& file, const std::string& from, const std::string& to) {
    const fs::path p = dir_ / file;
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    const auto pos = s.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    s.replace(pos, from.size(), to);
    std::ofstream(p) << s;
  }
  std::string Error() {
    try {
      VehicleSpec::Load((dir_ / "vehicle.yaml").string());
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }

 private:
  fs::path dir_;
  static inline int counter_ = 0;
};

TEST(Config, MissingFile) {
  try {
    VehicleSpec::Load("/nonexistent/vehicle.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/vehicle.yaml: cannot open"), std::string::npos) << e.what();
  }
}

TEST(Config, TheShippedVehicleLoads) {
  EXPECT_EQ(VehicleCopy().Error(), "");
  EXPECT_EQ(Vehicle::Build(VehicleSpec::Load(DM_CONFIG_DIR "/vehicles/hmmwv/vehicle.yaml"), Eigen::Vector3d::Zero())
                ->system()
                .num_bodies(),
            34);
}

TEST(Config, UnknownKey) {
  VehicleCopy c;
  c.Edit("tire.yaml", "n_lat: 24", "n_lat: 24\nradiuss: 0.5");
  const std::string e = c.Error();
  EXPECT_NE(e.find("tire.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key(s): radiuss"), std::string::npos) << e;
}

TEST(Config, MissingKey) {
  VehicleCopy c;
  c.Edit("tire.yaml", "width: 0.254", "");
  const std::string e = c.Error();
  EXPECT_NE(e.find("tire.yaml: width: missing required key"), std::string::npos) << e;
}

TEST(Config, NegativeMass) {
  VehicleCopy c;
  c.Edit("suspension_front.yaml", "upright: {mass: 19.45", "upright: {mass: -19.45");
  const std::string e = c.Error();
  EXPECT_NE(e.find("suspension_front.yaml: masses.upright.mass: value -19.45 must be positive"), std::string::npos) << e;
}

TEST(Config, NonPositiveDefiniteInertia) {
  VehicleCopy c;
  c.Edit("suspension_rear.yaml", "inertia: [0.166, 0.193, 0.044]", "inertia: [0.166, -0.193, 0.044]");
  const std::string e = c.Error();
  EXPECT_NE(e.find("suspension_rear.yaml: masses.upright.inertia"), std::string::npos) << e;
  EXPECT_NE(e.find("-0.193"), std::string::npos) << e;
}

TEST(Config, MalformedYaml) {
  VehicleCopy c;
  c.Edit("driveline.yaml", "final_drive_ratio: 0.2", "final_drive_ratio: [0.2");
  const std::string e = c.Error();
  EXPECT_NE(e.find("driveline.yaml: malformed YAML"), std::string::npos) << e;
}

TEST(Config, WrongTypeNamesTheValue) {
  VehicleCopy c;
  c.Edit("driveline.yaml", "final_drive_ratio: 0.2", "final_drive_ratio: fast");
  const std::string e = c.Error();
  EXPECT_NE(e.find("driveline.yaml: final_drive_ratio: expected a number, found 'fast'"), std::string::npos) << e;
}

TEST(Config, DifferentialIsOpenOrLocked) {
  VehicleCopy centre;
  centre.Edit("driveline.yaml", "centre_differential: locked", "centre_differential: welded");
  std::string e = centre.Error();
  EXPECT_NE(e.find("driveline.yaml: centre_differential: must be open or locked, not 'welded'"), std::string::npos)
      << e;
  VehicleCopy axles;
  axles.Edit("driveline.yaml", "axle_differentials: open", "axle_differentials: 1");
  e = axles.Error();
  EXPECT_NE(e.find("driveline.yaml: axle_differentials: must be open or locked, not '1'"), std::string::npos) << e;
  VehicleCopy missing;
  missing.Edit("driveline.yaml", "centre_differential: locked", "");
  e = missing.Error();
  EXPECT_NE(e.find("driveline.yaml: centre_differential: missing required key"), std::string::npos) << e;
}

TEST(Config, WheelbaseDiffersFromTheSuspensions) {
  VehicleCopy c;
  c.Edit("vehicle.yaml", "wheelbase: 3.378", "wheelbase: 3.0");
  const std::string e = c.Error();
  EXPECT_NE(e.find("vehicle.yaml: wheelbase: wheelbase 3 m differs from the suspensions' x_offset"), std::string::npos)
      << e;
}

TEST(Config, SprungMassBelowTheCarriedParts) {
  VehicleCopy c;
  c.Edit("vehicle.yaml", "sprung_mass: 4430.0", "sprung_mass: 50.0");
  const std::string e = c.Error();
  EXPECT_NE(e.find("vehicle.yaml: chassis.sprung_mass: sprung mass 50 kg is less than the"), std::string::npos) << e;
}

TEST(Config, HalfShaftWithoutLength) {
  VehicleCopy c;
  c.Edit("driveline.yaml", "inner_offset: 0.25", "inner_offset: 0.8");
  const std::string e = c.Error();
  EXPECT_NE(e.find("driveline.yaml: half_shaft: inner_offset and outer_inset leave no length"), std::string::npos) << e;
}

// What a checkpoint records of the files a run read: a record keeps the files read while it lives,
// by any thread, each path once with the bytes of its first reading; records nest; a file read
// while no record lives is kept nowhere (a process that reloads its files does not grow).
TEST(Config, InputFileRecordsKeepTheFilesReadWhileTheyLiveEachOnce) {
  const fs::path dir = fs::temp_directory_path() / ("dm_inputs_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return fs::absolute(dir / name).lexically_normal().string();
  };
  const std::string a = write("a.yaml", "x: 1\n"), b = write("b.yaml", "y: 2\n"), c = write("c.yaml", "z: 3\n");
  YamlReader::Load(c);  // no record alive
  InputFileRecord outer;
  YamlReader::Load(a);
  {
    InputFileRecord inner;
    YamlReader::Load(b);
    write("a.yaml", "x: 10\n");
    YamlReader::Load(a);
    YamlReader::Load(b);
    const std::vector<InputFile> in = inner.Files();
    ASSERT_EQ(in.size(), 2u);
    EXPECT_EQ(in[0].path, b);
    EXPECT_EQ(in[1].path, a);
    EXPECT_EQ(in[1].fingerprint, Fnv1a("x: 10\n", 6));  // its first reading in this record
  }
  std::thread([&] { YamlReader::Load(c); }).join();
  const std::vector<InputFile> out = outer.Files();
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].path, a);
  EXPECT_EQ(out[0].fingerprint, Fnv1a("x: 1\n", 5));
  EXPECT_EQ(out[1].path, b);
  EXPECT_EQ(out[1].fingerprint, Fnv1a("y: 2\n", 5));
  EXPECT_EQ(out[2].path, c);
  InputFileRecord later;
  EXPECT_TRUE(later.Files().empty());
  fs::remove_all(dir);
}

TEST(Config, RunnerExitsNonZeroWithTheMessage) {
  const std::string out = (fs::temp_directory_path() / "dm_runner_err.txt").string();
  const std::string cmd = std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/road_slope.yaml grade_deg=95 2> " + out;
  const int rc = std::system(cmd.c_str());
  EXPECT_NE(rc, 0);
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("road_slope.yaml: grade_deg: value 95 is outside the allowed range"), std::string::npos)
      << ss.str();
}

// What a command prints (stdout and stderr) and its exit status.
struct Command {
  int rc = -1;
  std::string out;
  explicit Command(const std::string& cmd) {
    const std::string file = (fs::temp_directory_path() / ("dm_cmd_" + std::to_string(::getpid()) + ".txt")).string();
    rc = std::system((cmd + " > " + file + " 2>&1").c_str());
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    out = ss.str();
    fs::remove(file);
  }
  int status() const { return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1; }
};

TEST(Config, RunnerHelpAndCheckRunNothing) {
  const Command help(std::string(DM_RUN_SCENE) + " --help");
  EXPECT_EQ(help.status(), 0);
  for (const char* s : {"--check", "soil_slope", "single_wheel", "exit status"}) EXPECT_NE(help.out.find(s), std::string::npos) << s;
  // --check reads the scene and every file it names, and prepares no soil: the soil scene at coarse
  // (a preparation of minutes) comes back at once with its verdict
  const Command good(std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/soil_slope.yaml --check");
  EXPECT_EQ(good.status(), 0) << good.out;
  EXPECT_NE(good.out.find("soil_slope.yaml: ok (soil_slope"), std::string::npos) << good.out;
  EXPECT_EQ(good.out.find("prepar"), std::string::npos) << good.out;
  // what a run refuses before it starts, the check refuses: a soil narrower than the track (in the
  // terrain file the scene names), a cone index outside the calibration table, a bad soil file
  const std::string soil = std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/soil_slope.yaml --check ";
  const Command narrow(soil + "terrain_overrides.levels.coarse.width=1.5");
  EXPECT_EQ(narrow.status(), 1);
  EXPECT_NE(narrow.out.find("soil_patch.yaml: levels.coarse.width: the soil (1.5 m wide) is narrower than the vehicle's track"),
            std::string::npos) << narrow.out;
  const Command ci(soil + "terrain_overrides.cone_index=900");
  EXPECT_EQ(ci.status(), 1);
  EXPECT_NE(ci.out.find("soil_patch.yaml: cone_index"), std::string::npos) << ci.out;
  const Command road(std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/road_slope.yaml --check terrain=/dev/zero");
  EXPECT_EQ(road.status(), 1);
  EXPECT_NE(road.out.find("/dev/zero: not a regular file"), std::string::npos) << road.out;
  for (const char* scene : {"road_slope", "single_wheel", "cone_penetrometer", "dem_pour", "uniaxial_compression"}) {
    const Command c(std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/" + scene + ".yaml --check");
    EXPECT_EQ(c.status(), 0) << scene << ": " << c.out;
  }
}

TEST(Config, EveryShippedFileReadsThroughItsFuzzTarget) {
  // the fuzzers' seeds are the shipped files: each reads and checks without any error, so that a
  // target that refused everything (a wrong folder, a wrong file name) cannot pass for a fuzzer
  for (const fuzz::Target& t : fuzz::Targets()) {
    const std::vector<std::string> seeds = t.seeds();
    EXPECT_FALSE(seeds.empty()) << t.name;
    for (size_t i = 0; i < seeds.size(); ++i) EXPECT_NO_THROW(t.read(seeds[i])) << t.name << " seed " << i;
  }
  // and a malformed one is refused with the file named
  try {
    fuzz::FindTarget("soil").read("density: [1");
    ADD_FAILURE() << "malformed soil read";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("soils/fuzz_input.yaml"), std::string::npos) << e.what();
  }
}

TEST(Config, TheFuzzersFindingsStayFixed) {
  // every input the fuzz harnesses found a defect with (test/fuzz/regressions/<target>/, see
  // scripts/sanitize.sh) reads as bad input now: a ConfigError, nothing else
  int inputs = 0;
  for (const fuzz::Target& t : fuzz::Targets()) {
    const fs::path dir = fs::path(DM_FUZZ_REGRESSIONS) / t.name;
    if (!fs::exists(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      std::ifstream in(e.path(), std::ios::binary);
      std::stringstream ss;
      ss << in.rdbuf();
      const std::string data = ss.str();
      EXPECT_NO_THROW(t.Run(reinterpret_cast<const std::uint8_t*>(data.data()), data.size())) << e.path();
      ++inputs;
    }
  }
  EXPECT_GT(inputs, 0) << DM_FUZZ_REGRESSIONS;
}

// A soil's strength is a cone index or a cohesion factor f. Where a file gives one and an override
// the other, the override's takes its place (an f given on the command line to the patch, whose
// file names CI 100, was dropped without a word before); both in one place is refused, naming the
// file and the key.
// A thing has one name: a key given under a name it had before (the launch files' f:= and mu:=
// reach the scene as the keys f and mu) is refused, the message naming the one name.
TEST(Config, AKeyUnderAnOldNameIsRefusedNamingItsOneName) {
  const std::string cone = DM_CONFIG_DIR "/scenes/cone_penetrometer.yaml";
  const std::string wheel = DM_CONFIG_DIR "/scenes/single_wheel.yaml";
  const std::string road = DM_CONFIG_DIR "/scenes/road_slope.yaml";
  const auto refused = [](const std::function<void()>& read, const std::string& expected) {
    try {
      read();
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused([&] { ConeParams::Read(YamlReader::LoadWithOverrides(cone, {"f=2"})); }, "f (now cohesion_factor)");
  refused([&] { SingleWheelParams::Read(YamlReader::LoadWithOverrides(wheel, {"mu=0.2"})); }, "mu (now friction)");
  refused([&] { MobilityRunParams::Read(YamlReader::LoadWithOverrides(road, {"grade=12"})); }, "grade (now grade_deg)");
  // the one names are taken
  EXPECT_DOUBLE_EQ(ConeParams::Read(YamlReader::LoadWithOverrides(cone, {"cohesion_factor=2"})).strength.cohesion_factor, 2.0);
  EXPECT_DOUBLE_EQ(SingleWheelParams::Read(YamlReader::LoadWithOverrides(wheel, {"friction=0.2"})).bin.friction, 0.2);
}

// The f of a row of the 0.06 m table (its CI is one of the table's rows, so no interpolation is
// involved): read from the table file as plain YAML, so that the test follows the table when it is
// remade and checks only which strength the overrides pick.
static double CoarseTableRowF(double ci) {
  const YAML::Node table = YAML::LoadFile(DM_CONFIG_DIR "/calibration/cone_index_mu0.1_d0.06.yaml")["table"];
  for (const auto& row : table) {
    if (row[0].as<double>() == ci) return row[1].as<double>();
  }
  ADD_FAILURE() << "the 0.06 m table has no row at CI " << ci;
  return std::nan("");
}

TEST(Config, AnOverriddenSoilStrengthTakesThePlaceOfTheFilesOther) {
  const std::string patch = DM_CONFIG_DIR "/terrains/soil_patch.yaml";  // cone_index: 100, coarse
  auto read = [&](const std::vector<std::string>& o) { return DemSoilParams::Read(YamlReader::LoadWithOverrides(patch, o)); };
  const double f100 = CoarseTableRowF(100.0), f50 = CoarseTableRowF(50.0);
  ASSERT_LT(f50, f100);
  // the file's CI 100 through the coarse table's row at CI 100
  const DemSoilParams file = read({});
  EXPECT_DOUBLE_EQ(file.strength.requested_cone_index_psi, 100.0);
  EXPECT_NEAR(file.strength.cohesion_factor, f100, 1e-9);
  // f 3 by an override: f 3, no requested CI; CI 50 by an override: the table's f at CI 50
  const DemSoilParams f3 = read({"cohesion_factor=3"});
  EXPECT_DOUBLE_EQ(f3.strength.cohesion_factor, 3.0);
  EXPECT_TRUE(std::isnan(f3.strength.requested_cone_index_psi));
  EXPECT_NEAR(read({"cone_index=50"}).strength.cohesion_factor, f50, 1e-9);
  // both by overrides: refused
  try {
    read({"cohesion_factor=3", "cone_index=50"});
    ADD_FAILURE() << "both overridden: accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("soil_patch.yaml: cohesion_factor: and cone_index are both given by overrides"),
              std::string::npos) << e.what();
  }
  // the cone scene's file gives f 1: a cone index override takes its place (coarse table, CI 50)
  const std::string cone = DM_CONFIG_DIR "/scenes/cone_penetrometer.yaml";
  const ConeParams c = ConeParams::Read(YamlReader::LoadWithOverrides(cone, {"fidelity=coarse", "cone_index=50"}));
  EXPECT_NEAR(c.strength.cohesion_factor, f50, 1e-9);
  EXPECT_DOUBLE_EQ(ConeParams::Read(YamlReader::LoadWithOverrides(cone, {"fidelity=coarse"})).strength.cohesion_factor, 1.0);
  // both in the file: refused (a copy of the patch's file with f added, its paths made absolute)
  const std::string dir = ::testing::TempDir() + "/both_strengths";
  std::filesystem::create_directories(dir);
  std::ifstream in(patch);
  std::stringstream text;
  text << in.rdbuf();
  std::string t = text.str();
  for (const std::string& rel : {std::string("../soils/"), std::string("../calibration")}) {
    const auto at = t.find(rel);
    ASSERT_NE(at, std::string::npos) << rel;
    t.replace(at, rel.size(), DM_CONFIG_DIR "/" + rel.substr(3));
  }
  std::ofstream(dir + "/both.yaml") << t << "cohesion_factor: 3\n";
  try {
    DemSoilParams::Read(YamlReader::Load(dir + "/both.yaml"));
    ADD_FAILURE() << "both in the file: accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("both.yaml: cohesion_factor: and cone_index are both given in the file"),
              std::string::npos) << e.what();
  }
}

TEST(Config, SceneTerrainOverridesTakeNestedKeysAsDottedOnes) {
  // terrain_overrides.levels.tiny.length=6 on the command line makes a nested map in the scene;
  // it overrides the terrain file's levels.tiny.length as a dotted key written in the scene does
  const std::string scene = DM_CONFIG_DIR "/scenes/soil_slope.yaml";
  const MobilityRunParams p = MobilityRunParams::Read(YamlReader::LoadWithOverrides(
      scene, {"terrain_overrides.levels.tiny.length=6", "terrain_overrides.cone_index=50", "terrain_overrides.fidelity=tiny",
              "terrain_overrides.patch.check_window=[0.3, 0.7]"}));
  const std::vector<std::string>& o = p.terrain_overrides;
  EXPECT_NE(std::find(o.begin(), o.end(), "levels.tiny.length=6"), o.end());
  EXPECT_NE(std::find(o.begin(), o.end(), "patch.check_window=[0.3, 0.7]"), o.end());
  EXPECT_NE(std::find(o.begin(), o.end(), "cone_index=50"), o.end());
  EXPECT_EQ(DescribeTerrain(p.terrain_file, o).fidelity, "tiny");
  // a misspelt nested key is the terrain file's unknown key, named with its path
  const MobilityRunParams bad =
      MobilityRunParams::Read(YamlReader::LoadWithOverrides(scene, {"terrain_overrides.levels.tiny.lenght=6"}));
  try {
    DescribeTerrain(bad.terrain_file, bad.terrain_overrides);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("lenght"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("soil_patch.yaml"), std::string::npos) << e.what();
  }
}

/// A run of dm_run_scene in a fresh folder of its own: `prefix` before the runner (timeout, prlimit),
/// `args` after the scene file; the result, the history, stdout and stderr go into the folder.
struct RunnerRun {
  fs::path dir;
  std::string result, history;
  int rc = -1;
  double wall = 0.0;  ///< [s] the whole command
  RunnerRun(const std::string& name, const std::string& prefix, const std::string& scene, const std::string& args)
      : dir(fs::temp_directory_path() / name), result((dir / "r.yaml").string()), history((dir / "h.csv").string()) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string cmd = prefix + " " + std::string(DM_RUN_SCENE) + " " DM_CONFIG_DIR "/scenes/" + scene + " " +
                            args + " --quiet --out " + result + " --history " + history + " > " +
                            (dir / "out.txt").string() + " 2> " + (dir / "err.txt").string();
    const auto t0 = std::chrono::steady_clock::now();
    rc = std::system(cmd.c_str());
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::string Err() const {
    std::ifstream in(dir / "err.txt");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
};

TEST(Config, RunnerInterruptedKeepsTheRunsResult) {
  // a 40 s road run sent SIGTERM after 3 s: it ends at the next step, writes its result (status
  // interrupted, the simulated time so far) and history, and exits 4
  const RunnerRun run("dm_runner_interrupt", "timeout --preserve-status -s TERM 3", "road_slope.yaml", "duration=40");
  ASSERT_TRUE(WIFEXITED(run.rc));
  EXPECT_EQ(WEXITSTATUS(run.rc), 4);
  EXPECT_LT(run.wall, 4.0);  // the signal at 3 s, then within a second
  const YAML::Node r = YAML::LoadFile(run.result);
  EXPECT_EQ(r["status"].as<std::string>(), "interrupted");
  EXPECT_TRUE(r["interrupted"].as<bool>());
  const double t = r["simulated_time"].as<double>();
  EXPECT_GT(t, 0.0);
  EXPECT_LT(t, 40.0);
  std::ifstream h(run.history);
  std::string line;
  long lines = 0;
  while (std::getline(h, line)) ++lines;
  EXPECT_GT(lines, 10);  // the samples so far (100 Hz)
}

TEST(Config, RunnerOnAFullDiskSaysSoAndKeepsTheResult) {
  // a road run whose history outgrows a file size limit (prlimit --fsize: as a full disk does): the
  // history's write fails, the result (small) says so naming the file, and the exit status is 3
  const RunnerRun run("dm_runner_full_disk", "prlimit --fsize=20000", "road_slope.yaml", "duration=3");
  ASSERT_TRUE(WIFEXITED(run.rc));
  EXPECT_EQ(WEXITSTATUS(run.rc), 3);
  EXPECT_LE(fs::file_size(run.history), 20000u);
  const YAML::Node r = YAML::LoadFile(run.result);
  EXPECT_EQ(r["status"].as<std::string>(), "error");
  const std::string why = r["error"].as<std::string>();
  EXPECT_NE(why.find(run.history + ": writing the history file failed"), std::string::npos) << why;
  EXPECT_GT(r["simulated_time"].as<double>(), 2.9);  // the run itself was made and is reported
  EXPECT_NE(run.Err().find("simulation error"), std::string::npos) << run.Err();
}

TEST(Config, RunnerInterruptedWhileTheSoilIsPreparedStopsWithinASecond) {
  // a soil scene (the tiny level: its preparation takes some 15-35 s here) sent SIGTERM 1 s after
  // its start, in the soil's preparation: it stops within a second of the signal (the preparation
  // polls the stop at every step), writes its result (status interrupted, the phase reached) and
  // the history's header, and exits 4 (without the prepared-soil cache: the soil is prepared)
  const RunnerRun run("dm_runner_interrupt_prep", "env -u DM_SOIL_CACHE timeout --preserve-status -s TERM 1", "soil_slope.yaml",
                      "terrain_overrides.fidelity=tiny terrain_overrides.threads=1");
  ASSERT_TRUE(WIFEXITED(run.rc));
  EXPECT_EQ(WEXITSTATUS(run.rc), 4);
  EXPECT_LT(run.wall, 2.0);  // 1 s to the signal, then within a second
  const YAML::Node r = YAML::LoadFile(run.result);
  EXPECT_EQ(r["status"].as<std::string>(), "interrupted");
  EXPECT_TRUE(r["interrupted"].as<bool>());
  const std::string why = r["error"].as<std::string>();
  EXPECT_NE(why.find("interrupted while the soil"), std::string::npos) << why;
  EXPECT_NE(why.find("being prepared: phase "), std::string::npos) << why;
  EXPECT_EQ(r["terrain_model"].as<std::string>(), "dem_soil");
  EXPECT_EQ(r["fidelity"].as<std::string>(), "tiny");
  EXPECT_EQ(r["simulated_time"].as<double>(), 0.0);
  std::ifstream h(run.history);
  std::string line;
  ASSERT_TRUE(static_cast<bool>(std::getline(h, line)));  // the header, no samples
  EXPECT_NE(line.find("speed"), std::string::npos) << line;
  EXPECT_FALSE(static_cast<bool>(std::getline(h, line)));
}

std::string FileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Config, RunnerStoppedWithACheckpointGoesOnFromItBitForBit) {
  // a 20 s road run: whole, then sent SIGTERM after 1 s with --checkpoint (it writes the
  // checkpoint where it stops, keeps it, and says so in its result), then taken up from it with
  // --restart: the result and the history are those of the whole run, to the last digit
  const fs::path dir = fs::temp_directory_path() / "dm_runner_checkpoint";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string ckpt = (dir / "run.ckpt").string(), args = "duration=20 result.end_when_steady=false";
  const RunnerRun whole("dm_runner_ckpt_whole", "", "road_slope.yaml", args + " --checkpoint " + (dir / "w.ckpt").string());
  ASSERT_EQ(whole.rc, 0) << whole.Err();
  EXPECT_FALSE(fs::exists(dir / "w.ckpt"));  // the run ended: its result is what remains
  EXPECT_GE(YAML::LoadFile(whole.result)["checkpoints_written"].as<int>(), 1);
  const RunnerRun stopped("dm_runner_ckpt_stopped", "timeout --preserve-status -s TERM 1", "road_slope.yaml",
                          args + " --checkpoint " + ckpt);
  ASSERT_TRUE(WIFEXITED(stopped.rc));
  ASSERT_EQ(WEXITSTATUS(stopped.rc), 4) << stopped.Err();
  const YAML::Node s = YAML::LoadFile(stopped.result);
  EXPECT_EQ(s["status"].as<std::string>(), "interrupted");
  EXPECT_EQ(s["checkpoint"].as<std::string>(), ckpt);
  const double at = s["checkpoint_at"].as<double>();
  EXPECT_GT(at, 0.0);
  EXPECT_LT(at, 20.0);
  ASSERT_TRUE(fs::exists(ckpt));
  // what it holds, for a person
  const Command info(std::string(DM_RUN_SCENE) + " --checkpoint-info " + ckpt);
  EXPECT_EQ(info.status(), 0) << info.out;
  for (const std::string& want : {std::string("scene: ") + DM_CONFIG_DIR + "/scenes/road_slope.yaml",
                                  std::string("overrides: duration=20 result.end_when_steady=false"),
                                  std::string("written by this build: yes"), std::string("vehicle.yaml: unchanged")})
    EXPECT_NE(info.out.find(want), std::string::npos) << want << "\n" << info.out;
  const RunnerRun rest("dm_runner_ckpt_rest", "", "road_slope.yaml", args + " --restart " + ckpt + " --checkpoint " + ckpt);
  ASSERT_EQ(rest.rc, 0) << rest.Err();
  const YAML::Node a = YAML::LoadFile(whole.result), c = YAML::LoadFile(rest.result);
  EXPECT_EQ(c["restarted_at"].as<double>(), at);
  for (const char* key : {"speed_made_good", "verdict", "steps", "exchanges", "simulated_time", "drawbar_margin",
                          "vehicle_energy_dissipated", "vehicle_energy_kinetic"})
    EXPECT_EQ(c[key].as<std::string>(), a[key].as<std::string>()) << key;
  EXPECT_EQ(FileText(rest.history), FileText(whole.history));  // every sample, byte for byte
  EXPECT_FALSE(fs::exists(ckpt));

  // what the runner refuses: checkpoints of a scene that is no mobility run, a period that is no
  // number of seconds, a restart with other overrides (naming the checkpoint and what differs)
  const RunnerRun pour("dm_runner_ckpt_pour", "", "dem_pour.yaml", "--checkpoint " + ckpt);
  EXPECT_EQ(WEXITSTATUS(pour.rc), 1);
  EXPECT_NE(pour.Err().find("--checkpoint and --restart are for mobility runs"), std::string::npos) << pour.Err();
  const RunnerRun every("dm_runner_ckpt_every", "", "road_slope.yaml", "--checkpoint " + ckpt + " --checkpoint-every 0");
  EXPECT_EQ(WEXITSTATUS(every.rc), 2);
  EXPECT_NE(every.Err().find("--checkpoint-every 0"), std::string::npos) << every.Err();
  const RunnerRun again("dm_runner_ckpt_again", "timeout --preserve-status -s TERM 1", "road_slope.yaml",
                        args + " --checkpoint " + ckpt);
  ASSERT_TRUE(fs::exists(ckpt)) << again.Err();
  const RunnerRun other("dm_runner_ckpt_other", "", "road_slope.yaml", "duration=20 --restart " + ckpt);
  EXPECT_EQ(WEXITSTATUS(other.rc), 1);
  EXPECT_NE(other.Err().find(ckpt + ": checkpoint of the run of"), std::string::npos) << other.Err();
  EXPECT_NE(other.Err().find("overrides"), std::string::npos) << other.Err();
}

TEST(Config, RunnerStoppedRigGoesOnFromItsCheckpointToTheSameConeIndex) {
  // the tiny cone (some 3 s) sent SIGTERM after 1 s with --checkpoint, then taken up with
  // --restart: the cone index of the run that never stopped, to the last digit (the rigs' own
  // test, rig_checkpoint_test, takes them up from each phase)
  const fs::path dir = fs::temp_directory_path() / "dm_runner_rig_checkpoint";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string ckpt = (dir / "cone.ckpt").string(), args = "fidelity=tiny cohesion_factor=2 threads=1";
  const RunnerRun whole("dm_runner_rig_whole", "", "cone_penetrometer.yaml", args);
  ASSERT_EQ(whole.rc, 0) << whole.Err();
  const RunnerRun stopped("dm_runner_rig_stopped", "timeout --preserve-status -s TERM 1", "cone_penetrometer.yaml",
                          args + " --checkpoint " + ckpt);
  ASSERT_TRUE(WIFEXITED(stopped.rc));
  ASSERT_EQ(WEXITSTATUS(stopped.rc), 4) << stopped.Err();
  const YAML::Node s = YAML::LoadFile(stopped.result);
  EXPECT_EQ(s["status"].as<std::string>(), "interrupted");
  EXPECT_EQ(s["checkpoint"].as<std::string>(), ckpt);
  ASSERT_TRUE(fs::exists(ckpt));
  const RunnerRun rest("dm_runner_rig_rest", "", "cone_penetrometer.yaml", args + " --restart " + ckpt + " --checkpoint " + ckpt);
  ASSERT_EQ(rest.rc, 0) << rest.Err();
  const YAML::Node a = YAML::LoadFile(whole.result), c = YAML::LoadFile(rest.result);
  EXPECT_EQ(c["restarted_at"].as<double>(), s["checkpoint_at"].as<double>());
  for (const char* key : {"cone_index_psi", "cone_index_std_psi", "steps", "simulated_time", "surface_height"})
    EXPECT_EQ(c[key].as<std::string>(), a[key].as<std::string>()) << key;
  EXPECT_FALSE(fs::exists(ckpt));  // the run ended: its result is what remains
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dem_mobility::core
