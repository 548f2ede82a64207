// The co-simulation's plumbing: the terrain lifecycle through a port, the coupling interval the
// terrain advances by, the registries' errors, the one result file, and the soil preparation's
// phases.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/cosim_loop.h"
#include "dem_mobility/core/mobility/mobility_run.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/tools/scene_runners.h"
#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

// A terrain that records what the port asks of it, in order.
class RecordingTerrain final : public TerrainModel {
 public:
  const TerrainDescription& description() const override { return d_; }
  void Synchronize(long step, double t, const std::vector<WheelState>& states) override {
    calls.push_back("synchronize " + std::to_string(step));
    t_ = t;
    n_ = static_cast<int>(states.size());
  }
  void GetWrenches(std::vector<WheelWrench>* w) const override {
    calls.push_back("wrenches");
    w->assign(n_, WheelWrench());
    (*w)[0].force.z() = t_;  // the state it was synchronized with
  }
  void Advance(double dt) override { calls.push_back("advance " + std::to_string(dt)); }
  const TriMesh& Surface() const override { return mesh_; }
  void SaveState(StateWriter& out) const override { out(t_, n_); }
  void LoadState(StateReader& in) override { in(t_, n_); }
  mutable std::vector<std::string> calls;

 private:
  TerrainDescription d_;
  TriMesh mesh_;
  double t_ = 0.0;
  int n_ = 0;
};

TEST(TerrainPort, SynchronizesAnswersThenAdvances) {
  RecordingTerrain terrain;
  LocalTerrainPort port(terrain);
  std::vector<WheelWrench> w;
  port.Exchange(7, 0.25, 1e-3, std::vector<WheelState>(kWheels), &w);
  EXPECT_EQ(terrain.calls, (std::vector<std::string>{"synchronize 7", "wrenches", "advance " + std::to_string(1e-3)}));
  ASSERT_EQ(w.size(), static_cast<size_t>(kWheels));
  EXPECT_EQ(w[0].force.z(), 0.25);
}

// The vehicle exchanges every coupling interval and the terrain advances by the whole interval.
TEST(VehicleCoSim, TerrainAdvancesByTheCouplingInterval) {
  MobilityRunParams p = MobilityRunParams::Read(YamlReader::Load(DM_CONFIG_DIR "/scenes/road_slope.yaml"));
  p.coupling_interval = 4;
  const VehicleSpec spec = VehicleSpec::Load(p.vehicle_file);
  const std::unique_ptr<TerrainModel> road = LoadTerrainModel(p.terrain_file, TerrainVehicle{spec.tire, kWheels});
  struct Recorder final : public TerrainPort {
    explicit Recorder(TerrainModel& m) : local(m) {}
    void Exchange(long step, double t, double dt, const std::vector<WheelState>& s,
                  std::vector<WheelWrench>* w) override {
      steps.push_back(step);
      dts.push_back(dt);
      local.Exchange(step, t, dt, s, w);
    }
    const TerrainDescription& description() const override { return local.description(); }
    LocalTerrainPort local;
    std::vector<long> steps;
    std::vector<double> dts;
  } port(*road);
  VehicleCoSim sim(p, spec);
  sim.Start(port);
  for (int k = 0; k < 12; ++k) sim.Step(port);
  EXPECT_EQ(port.steps, (std::vector<long>{0, 4, 8, 12}));  // the opening exchange, then every 4th step
  EXPECT_EQ(port.dts[0], 0.0);
  for (size_t k = 1; k < port.dts.size(); ++k) EXPECT_EQ(port.dts[k], 4.0 * sim.dt());
  // the result names the terrain that ran
  EXPECT_EQ(port.description().model, "rigid_road");
  EXPECT_EQ(port.description().cone_index, 300.0);
}

TEST(Registries, UnknownKindsAreRefusedNamingFileKeyAndTheKnownOnes) {
  const std::string terrain = WriteTemp("bad_terrain.yaml", "model: swamp\n");
  try {
    LoadTerrainModel(terrain, TerrainVehicle{});
    FAIL() << "an unknown terrain model was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(terrain + ": model"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rigid_road"), std::string::npos) << e.what();
  }
  const YamlReader scene = YamlReader::FromString("scene: moon_walk\n", "s.yaml");
  try {
    FindSceneKind(scene);
    FAIL() << "an unknown scene kind was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml: scene"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cone_penetrometer"), std::string::npos) << e.what();
  }
  // a mobility scene is a scene but no soil rig
  const YamlReader road = YamlReader::Load(DM_CONFIG_DIR "/scenes/road_slope.yaml");
  EXPECT_EQ(FindSceneKind(road).scene, "road_slope");
  EXPECT_FALSE(IsSoilRigScene("road_slope"));
  EXPECT_TRUE(IsSoilRigScene("cone_penetrometer"));
  EXPECT_THROW(MakeSoilRig(road), ConfigError);
}

TEST(ResultFile, OneSchemaAndExactDoubles) {
  ResultFile f("scenes/x.yaml", "dem_pour");
  const double third = 1.0 / 3.0, tiny = std::numeric_limits<double>::denorm_min();
  f.Set("a", third).Set("b", tiny).SetFlow("c", {0.1, 0.2});
  f.SetStatus("error", "it broke");
  const YAML::Node n = YAML::Load(f.Text());
  std::vector<std::string> keys;
  for (const auto& kv : n) keys.push_back(kv.first.as<std::string>());
  EXPECT_EQ(keys, (std::vector<std::string>{"scene", "kind", "status", "error", "a", "b", "c"}));
  EXPECT_EQ(n["status"].as<std::string>(), "error");
  EXPECT_EQ(n["a"].as<double>(), third);
  EXPECT_EQ(n["b"].as<double>(), tiny);
  EXPECT_THROW(f.Set("status", 1), std::logic_error);  // the schema's keys are not figures
  EXPECT_THROW(f.Write("/nonexistent-dir/r.yaml"), ConfigError);
}

// A preparation phase of zero duration takes no DEM step; the others run in order.
TEST(SoilPreparation, PhasesInOrderAndZeroDurationsTakeNoStep) {
  DemSystem s(Nominal(), DemSettings());
  for (DemWall& w : MakeOpenBoxWalls(0.3, 0.3, 0.3)) s.AddWall(std::move(w));
  DemWall lid = MakeQuadWall("lid", {0, 0, 0}, {0, 0.3, 0}, {0.3, 0, 0});
  lid.position.z() = 0.3;
  const int l = s.AddWall(lid);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) s.AddParticle(Eigen::Vector3d(0.05 + 0.05 * i, 0.05 + 0.05 * j, 0.0151));
  s.Finalize(1.5e-5);
  SoilPreparationParams p;
  p.settle_time = 0.0;
  p.hold_time = 0.01;
  p.release_time = 0.0;
  p.lid_speed = 0.5;
  SoilPreparation prep(&s, l, 0.09, 0.3, p, "test");
  prep.Step();
  EXPECT_EQ(prep.phase(), SoilPreparation::Phase::kConsolidate);
  EXPECT_EQ(s.step_count(), 0);
  std::vector<SoilPreparation::Phase> seen{prep.phase()};
  long release_start = -1;
  while (!prep.done()) {
    prep.Step();
    if (prep.phase() != seen.back()) seen.push_back(prep.phase());
    if (prep.phase() == SoilPreparation::Phase::kRelease) release_start = s.step_count();
  }
  EXPECT_EQ(seen, (std::vector<SoilPreparation::Phase>{
                      SoilPreparation::Phase::kConsolidate, SoilPreparation::Phase::kRetreat,
                      SoilPreparation::Phase::kRelease, SoilPreparation::Phase::kDone}));
  EXPECT_EQ(s.step_count(), release_start);  // the release of zero duration took no step
  // the lid held the pressure it was asked for (the mean over the hold) and went back to its park
  EXPECT_NEAR(prep.lid_pressure_reached(), p.lid_pressure, 0.1 * p.lid_pressure);
  EXPECT_EQ(s.wall(l).position.z(), 0.3);
  EXPECT_GT(prep.height_poured(), 0.0);
}

}  // namespace
}  // namespace dem_mobility::core

namespace dem_mobility::core {
namespace {

TEST(SteadyWindow, MeansOverTheWindowAndTheDrawbarMarginBeyondTheGrade) {
  // a history whose last 2 s hold constant figures and whose earlier samples differ
  std::vector<MobilitySample> h;
  for (int k = 0; k <= 500; ++k) {
    MobilitySample s{0.01 * k, 0.0, 5.0, 5.0, 0.0, 0.0, 0.0, true};
    const bool window = s.t >= 5.0 - 2.0 - 1e-9;
    for (int i = 0; i < kWheels; ++i) {
      s.slip[i] = window ? 0.1 * (i + 1) : 0.9;
      s.sinkage[i] = window ? 0.01 * (i + 1) : 0.5;
    }
    s.traction = window ? 12000.0 : -1.0;
    s.thrust = window ? 15000.0 : 0.0;
    h.push_back(s);
  }
  const double m = 5000.0, grade = 10.0, wn = m * 9.81 * std::cos(grade * M_PI / 180.0);
  const SteadyFigures f = SteadyWindowFigures(h, 2.0, m, grade);
  EXPECT_EQ(f.samples, 201);
  for (int i = 0; i < kWheels; ++i) {
    EXPECT_NEAR(f.slip[i], 0.1 * (i + 1), 1e-12);
    EXPECT_NEAR(f.sinkage[i], 0.01 * (i + 1), 1e-12);
  }
  EXPECT_NEAR(f.traction_coefficient, 12000.0 / wn, 1e-12);
  EXPECT_NEAR(f.motion_resistance, 3000.0 / wn, 1e-12);
  EXPECT_NEAR(f.drawbar_margin, 12000.0 / wn - std::tan(grade * M_PI / 180.0), 1e-12);
}

// A stall is the speed under stall_speed for stall_time on end while the command asks for more:
// a start that crawls for less than that, or a vehicle that slows down for a moment, is not one.
TEST(SpeedMadeGood, NoGoOnlyAfterAWholeStallWhileTheCommandAsksForMore) {
  const PlateauParams p;  // 0.2 m/s for 5 s
  // 100 Hz samples to t_end; speed(t), command 1 m/s^2
  auto history = [](double t_end, const std::function<double(double)>& speed) {
    std::vector<MobilitySample> h;
    for (int k = 0; k * 0.01 <= t_end + 1e-9; ++k) {
      const double t = 0.01 * k;
      h.push_back(MobilitySample{t, 0.0, speed(t), t, 0.0, 0.0, 0.0, true});
    }
    return h;
  };
  // crawling for 4.3 s from the start, then moving: no stall
  const auto slow_start = history(10.0, [](double t) { return t < 4.3 ? 0.1 : 3.0; });
  EXPECT_EQ(StalledFor(slow_start, p.stall_speed), 0.0);
  EXPECT_NE(DetectSpeedMadeGood(slow_start, p, 25.0).status, "no_go");
  // moving, then under 0.2 m/s from t = 7.5: stalled for 1.2 s at 8.7 s (no verdict yet), for
  // 5 s at 12.5 s (no-go)
  const auto slows = [](double t) { return t < 7.5 ? 6.0 : 0.1; };
  EXPECT_NEAR(StalledFor(history(8.7, slows), p.stall_speed), 1.2, 0.011);
  EXPECT_NE(DetectSpeedMadeGood(history(8.7, slows), p, 25.0).status, "no_go");
  EXPECT_NEAR(StalledFor(history(12.5, slows), p.stall_speed), 5.0, 0.011);
  EXPECT_EQ(DetectSpeedMadeGood(history(12.6, slows), p, 25.0).status, "no_go");
  // never moving: stalled from when the command passed 0.2 m/s (t = 0.2 s)
  const auto never = history(5.3, [](double) { return 0.0; });
  EXPECT_NEAR(StalledFor(never, p.stall_speed), 5.1, 0.011);
  EXPECT_EQ(DetectSpeedMadeGood(never, p, 25.0).status, "no_go");
  // at 5.1 s (stalled for 4.9 s) not yet no-go, and no plateau either: a flat speed under 0.2 m/s
  // is a stall in the making
  EXPECT_EQ(DetectSpeedMadeGood(history(5.1, [](double) { return 0.0; }), p, 25.0).status, "not_steady");
}

// A plateau is a flat and quiet window: a speed that rises and falls within the window fits a
// flat line but is no plateau; a flat speed with DEM-like noise is one.
TEST(SpeedMadeGood, SteadyIsFlatAndQuietNotARiseAndFall) {
  const PlateauParams p;  // 5 s window, |slope| <= 0.05 m/s^2, rms about the line <= 10 % of the mean,
                          // |slope| over the trailing 2.5 s <= 0.1 m/s^2
  auto history = [](const std::function<double(double)>& speed) {
    std::vector<MobilitySample> h;
    for (int k = 0; k <= 900; ++k) h.push_back(MobilitySample{0.01 * k, 0.0, speed(0.01 * k), 0.01 * k, 0.0, 0.0,
                                                              0.0, true});
    return h;
  };
  // up from 2 m/s to 6 m/s at 6.5 s and down again by 9 s (the soil gave way): symmetric about the
  // window's middle, so its fitted line is flat (the slope alone would call it steady at 4 m/s)
  const auto rise_fall = history([](double t) { return t < 4.0 ? 2.0 : 6.0 - 1.6 * std::abs(t - 6.5); });
  const SpeedMadeGood rf = DetectSpeedMadeGood(rise_fall, p, 25.0);
  EXPECT_LT(std::abs(rf.window_slope), p.tolerance);
  EXPECT_EQ(rf.status, "not_steady");
  // 4 m/s with +-0.3 m/s of noise (a 7 Hz wobble, rms 0.21 m/s: 5 % of the mean): steady at 4
  const SpeedMadeGood flat = DetectSpeedMadeGood(history([](double t) { return 4.0 + 0.3 * std::sin(44.0 * t); }), p, 25.0);
  EXPECT_EQ(flat.status, "steady");
  EXPECT_NEAR(flat.value, 4.0, 0.02);
  // the same wobble about 2 m/s is 10.6 % of the mean: above the 10 % scatter, no plateau
  EXPECT_EQ(DetectSpeedMadeGood(history([](double t) { return 2.0 + 0.3 * std::sin(44.0 * t); }), p, 25.0).status,
            "not_steady");
  // a hump: up at 0.4 m/s^2 to 11.9 m/s at 6.5 s and down at 0.4 m/s^2 to 10.9 m/s at 9 s: the
  // whole window's line is flat and its scatter 2.5 % of the mean; the trailing half falls at
  // 0.4 m/s^2, four times the end tolerance: no plateau
  const auto hump = history([](double t) { return t < 4.0 ? 10.9 : 11.9 - 0.4 * std::abs(t - 6.5); });
  const SpeedMadeGood hu = DetectSpeedMadeGood(hump, p, 25.0);
  EXPECT_LT(std::abs(hu.window_slope), p.tolerance);
  EXPECT_NEAR(hu.end_slope, -0.4, 1e-9);
  EXPECT_EQ(hu.status, "not_steady");
  // a rise that has ended: up at 0.08 m/s^2 over the window's first half, flat over the second
  // (the vehicle reached its speed 2.5 s ago; the whole window's slope 0.04 m/s^2): steady
  const SpeedMadeGood settled = DetectSpeedMadeGood(
      history([](double t) { return t < 6.5 ? 10.0 + 0.08 * (t - 4.0) * (t > 4.0) : 10.2; }), p, 25.0);
  EXPECT_NEAR(settled.window_slope, 0.04, 0.002);
  EXPECT_EQ(settled.status, "steady") << settled.window_slope;
}

// Speed-made-good is the level speed with the engine at full torque for its speed (paper section
// 4.3): a level speed below the command with the engine held back (the driver's own limit) is
// none, a level speed at the command without full throttle is command-limited, and one at full
// throttle is steady wherever it lies.
TEST(SpeedMadeGood, SteadyOnlyWithTheEngineAtFullThrottle) {
  const PlateauParams p;  // at least half the window's samples at full throttle
  ASSERT_DOUBLE_EQ(p.full_throttle, 0.5);
  // 9 s at 100 Hz, a flat 10 m/s with a small wobble; the command `command`; full throttle in
  // every k-th sample of the window (k = 0: none)
  auto history = [](double speed, double command, int k) {
    std::vector<MobilitySample> h;
    for (int i = 0; i <= 900; ++i) {
      const double t = 0.01 * i;
      h.push_back(MobilitySample{t, 0.0, speed + 0.05 * std::sin(30.0 * t), command, 0.0, 0.0, 0.0,
                                 k > 0 && i % k == 0});
    }
    return h;
  };
  // at full throttle throughout, or in every other sample (half the window): steady at 10 m/s
  for (int k : {1, 2}) {
    const SpeedMadeGood s = DetectSpeedMadeGood(history(10.0, 20.0, k), p, 25.0);
    EXPECT_EQ(s.status, "steady") << k;
    EXPECT_NEAR(s.value, 10.0, 0.01);
  }
  // in every third sample (a third of the window) or never, 10 m/s under a command of 20: not yet
  // a speed-made-good (the old detector called both steady)
  EXPECT_EQ(DetectSpeedMadeGood(history(10.0, 20.0, 3), p, 25.0).status, "not_steady");
  EXPECT_EQ(DetectSpeedMadeGood(history(10.0, 20.0, 0), p, 25.0).status, "not_steady");
  // at the command's top speed (24.8 of 25 m/s) without full throttle, or with it in a third of the
  // samples: command-limited; with it in every sample: steady there (the engine's own limit)
  EXPECT_EQ(DetectSpeedMadeGood(history(24.8, 25.0, 0), p, 25.0).status, "command_limited");
  EXPECT_EQ(DetectSpeedMadeGood(history(24.8, 25.0, 3), p, 25.0).status, "command_limited");
  EXPECT_EQ(DetectSpeedMadeGood(history(24.8, 25.0, 1), p, 25.0).status, "steady");
  // the share is the scene's: a quarter lets the every-third-sample history count
  PlateauParams quarter = p;
  quarter.full_throttle = 0.25;
  EXPECT_EQ(DetectSpeedMadeGood(history(10.0, 20.0, 3), quarter, 25.0).status, "steady");
}

TEST(VehicleCoSim, EndsWhenSteadyIfAskedWithTheSpeedOfTheFullRun) {
  // the road at 20 deg: WOT-limited at about 13 m/s after ~15 s; asked to end when steady, the
  // run stops well before its 40 s with the same verdict and speed as the run that goes on
  MobilityRunParams p = MobilityRunParams::Read(
      YamlReader::LoadWithOverrides(DM_CONFIG_DIR "/scenes/road_slope.yaml", {"grade_deg=20", "duration=30"}));
  const MobilityRunResult full = MobilityRun(p).Run();
  p.end_when_steady = true;
  const MobilityRunResult early = MobilityRun(p).Run();
  ASSERT_TRUE(full.error.empty() && early.error.empty()) << full.error << early.error;
  ASSERT_EQ(full.smg.status, "steady");
  EXPECT_EQ(early.smg.status, "steady");
  EXPECT_TRUE(early.ended_early);
  EXPECT_LT(early.sim_time, 0.9 * full.sim_time);
  EXPECT_NEAR(early.smg.value, full.smg.value, 0.01 * full.smg.value);
}

/// Stops a run at the start of vehicle step `at`, writing a checkpoint there first.
struct CheckpointAt final : public CoSimObserver {
  CheckpointAt(const MobilityRun& run, long at, std::string path, CheckpointIdentity id)
      : run_(run), at_(at), path_(std::move(path)), id_(std::move(id)) {}
  void AtStepStart(const VehicleCoSim& sim, const CoSimLoopState& st) override {
    if (!stop_ && sim.step() == at_) {
      run_.WriteCheckpoint(path_, id_, st);
      stop_ = true;
    }
  }
  bool StopRequested() override { return stop_; }
  const MobilityRun& run_;
  long at_;
  std::string path_;
  CheckpointIdentity id_;
  bool stop_ = false;
};

/// Every figure of two histories the same, bit for bit (EXPECT_EQ on doubles: no tolerance).
void ExpectSameHistory(const std::vector<MobilitySample>& a, const std::vector<MobilitySample>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i) + " (t = " + std::to_string(a[i].t) + " s)");
    EXPECT_EQ(a[i].t, b[i].t);
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].speed, b[i].speed);
    EXPECT_EQ(a[i].drive_torque, b[i].drive_torque);
    EXPECT_EQ(a[i].brake_effort, b[i].brake_effort);
    EXPECT_EQ(a[i].traction, b[i].traction);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_EQ(a[i].heading, b[i].heading);
    for (int w = 0; w < kWheels; ++w) {
      EXPECT_EQ(a[i].slip[w], b[i].slip[w]);
      EXPECT_EQ(a[i].sinkage[w], b[i].sinkage[w]);
    }
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(Checkpoint, ARoadRunTakenUpAgainIsTheRunThatNeverStopped) {
  // a copy of the road scene (its vehicle and terrain by absolute path) that the test may change
  std::ifstream in(DM_CONFIG_DIR "/scenes/road_slope.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  for (const char* key : {"vehicle: ../", "terrain: ../"}) {
    const size_t at = text.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at, std::string(key).size(), std::string(key).substr(0, 9) + DM_CONFIG_DIR "/");
  }
  const std::string scene = WriteTemp("checkpoint_road_scene.yaml", text);
  const std::string ckpt = ::testing::TempDir() + "checkpoint_road.ckpt";
  const std::vector<std::string> overrides = {"grade_deg=10", "duration=1.5", "result.end_when_steady=false"};
  InputFileRecord inputs;
  const MobilityRunParams p = MobilityRunParams::Read(YamlReader::LoadWithOverrides(scene, overrides));

  MobilityRun whole(p);
  const MobilityRunResult a = whole.Run();
  ASSERT_TRUE(a.error.empty()) << a.error;
  CheckpointIdentity id;
  id.scene_file = std::filesystem::absolute(scene).lexically_normal().string();
  id.overrides = overrides;
  id.files = inputs.Files();
  id.executable = ExecutableFingerprint();
  ASSERT_GE(id.files.size(), 3u);  // the scene, the vehicle's files, the road

  // the same run stopped at a step of the driving (the driver's integral, the tires' anchors and the
  // history all under way), written there, and taken up again from the file
  MobilityRun first(p);
  const long at = first.sim().settle_steps() + (a.steps - first.sim().settle_steps()) / 2 + 7;
  CheckpointAt stopper(first, at, ckpt, id);
  const MobilityRunResult b = first.Run(&stopper);
  ASSERT_TRUE(b.interrupted);
  ASSERT_LT(b.history.size(), a.history.size());
  CoSimLoopState loop;
  CheckpointIdentity read;
  std::unique_ptr<MobilityRun> rest = MobilityRun::FromCheckpoint(ckpt, p, scene, overrides, &loop, &read);
  EXPECT_EQ(read.step, at);
  EXPECT_EQ(rest->sim().step(), at);
  EXPECT_EQ(rest->dt(), whole.dt());
  const MobilityRunResult c = rest->Run(nullptr, &loop);
  ASSERT_TRUE(c.error.empty()) << c.error;
  EXPECT_FALSE(c.interrupted);
  EXPECT_EQ(c.steps, a.steps);
  EXPECT_EQ(c.exchanges, a.exchanges);
  EXPECT_EQ(c.driver_updates, a.driver_updates);
  ExpectSameHistory(a.history, c.history);
  EXPECT_EQ(c.smg.value, a.smg.value);
  EXPECT_EQ(c.vehicle_energy.dissipated, a.vehicle_energy.dissipated);
  EXPECT_EQ(c.vehicle_ledger.least, a.vehicle_ledger.least);
  const Eigen::Vector3d xa = whole.vehicle().ChassisFramePosition(), xc = rest->vehicle().ChassisFramePosition();
  EXPECT_TRUE((xa.array() == xc.array()).all()) << xa.transpose() << " vs " << xc.transpose();
  // the wall time goes on from the part before
  EXPECT_GE(c.wall_time, loop.r.wall_time);

  // what a restart refuses, naming the checkpoint and what differs
  const auto refused = [&](const std::string& file, const std::vector<std::string>& ovr, const std::string& what) {
    CoSimLoopState l;
    try {
      MobilityRun::FromCheckpoint(file, p, scene, ovr, &l);
      ADD_FAILURE() << "no error for " << what;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(ckpt, {"grade_deg=12", "duration=1.5", "result.end_when_steady=false"}, "overrides");
  std::ifstream ck(ckpt, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(ck)), std::istreambuf_iterator<char>());
  // cut short, or a byte changed: the checksum says so before anything is read
  refused(WriteTemp("checkpoint_cut.ckpt", bytes.substr(0, bytes.size() / 2)), overrides, "damaged");
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  refused(WriteTemp("checkpoint_flipped.ckpt", flipped), overrides, "damaged");
  // a file whose checksum holds but whose state ends early (written by a program that wrote less)
  std::string short_state = bytes.substr(0, bytes.size() - sizeof(uint64_t) - 100);
  const uint64_t sum = Fnv1a(short_state.data(), short_state.size());
  short_state.append(reinterpret_cast<const char*>(&sum), sizeof(sum));
  refused(WriteTemp("checkpoint_short.ckpt", short_state), overrides, "early");
  std::string other = bytes;
  other[0] = 'X';
  refused(WriteTemp("checkpoint_other.ckpt", other), overrides, "not a dem_mobility checkpoint");
  refused(::testing::TempDir() + "no_such.ckpt", overrides, "cannot open");
  // an input file changed since the run began (a comment is a change: the bytes are what count)
  std::ofstream(scene, std::ios::app) << "# changed\n";
  refused(ckpt, overrides, "has changed");
}

}  // namespace
}  // namespace dem_mobility::core
