// soil_scene: the vehicle on the moving soil patch, per fidelity level. For each level: the soil
// prepared (its wall time), the vehicle settled and driving, then two timed windows of the whole
// coupled step (vehicle, tires, patch emission and leveling, soil): 0.2 s into the drive (before
// the patch follows), and once the patch has followed the vehicle for DM_SOIL_FOLLOW s (0.3; the
// emitter laying soil ahead); wall seconds per simulated second, and particle-steps per second of
// the coupled step against the bare soil patch (the same soil, in the same state, with the tires
// and tools lifted clear and no patch) over the same steps. The LEVEL_rate_ratio and
// LEVEL_wall_s_per_sim_s lines (and the mean rate_ratio_to_bare_soil) are the following window's.
// A level named in DM_SOIL_ONE_WINDOW (comma-separated; bench.sh names paper) is timed in the first
// window only: the patch follows only once the vehicle has driven 1.65 m (seconds of simulated
// time, hours at 620,000 particles), so its LEVEL_* lines are that window's, a '#' line says so, and
// it is left out of the mean ratio.
//   soil_scene_bench SCENE.yaml LEVEL[,LEVEL...] [window_s] [[LEVEL:]key=value ...]
// (an override LEVEL:key=value applies to that level only: a cohesion factor where the level has no
// calibration table, a shortened preparation)
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/cosim_loop.h"
#include "dem_mobility/core/mobility/mobility_run.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

using namespace dem_mobility::core;

namespace {
double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Times two windows of the whole coupled step in one run, each against the bare soil in the same
/// state: 0.2 s into the drive (the wheels rolling, the patch in place, nothing emitted yet), and
/// once the patch has followed the vehicle for `follow` s (the emitter laying soil ahead, the
/// leveling tools moving: what most of a run's simulated time is). It sees every step of the run
/// (the vehicle's steps, the soil's every exchange, the driver): a window's wall time is that of
/// its steps; the bare soil is timed at the window's end, between two steps of the run, which then
/// goes on.
struct Windows final : public CoSimObserver {
  const DemSoilTerrain* soil = nullptr;
  const SoilPatch* patch = nullptr;
  std::string level;
  int n = 0;
  long window_steps = 0;
  double follow = 0.0, following_since = -1.0, ratio = 0.0;
  int done = 0;  // windows finished
  int wanted = 2;  // windows to time
  long at = -1;  // the step the window in progress began at (-1: none)
  long soil0 = 0, nb0 = 0, wb0 = 0, re0 = 0;
  double t_begin = 0.0;
  std::chrono::steady_clock::time_point t0;
  void OnStep(const VehicleCoSim& s, const DriverCommand&) override {
    const DemSystem& dem = soil->bin().dem();
    if (patch && patch->stats().following && following_since < 0.0) following_since = s.time();
    if (at < 0) {
      Begin(s, dem);
      return;
    }
    if (s.step() - at >= window_steps) Finish(s, dem);
  }
  /// Begins a window when its time has come.
  void Begin(const VehicleCoSim& s, const DemSystem& dem) {
    const bool begin = done == 0 ? s.driver_time() >= 0.2
                                 : following_since >= 0.0 && s.time() - following_since >= follow;
    if (!begin) return;
    at = s.step();
    t_begin = s.time();
    soil0 = dem.step_count();
    nb0 = dem.neighbour_builds();
    wb0 = dem.wall_builds();
    re0 = patch ? patch->stats().reemitted : 0;
    t0 = std::chrono::steady_clock::now();
  }
  /// Ends the window: the bare soil timed over as many steps, the window's lines printed.
  void Finish(const VehicleCoSim& s, const DemSystem& dem) {
    const double coupled = Seconds(t0);
    const long soil_steps = dem.step_count() - soil0;
    const long nb = dem.neighbour_builds() - nb0, wb = dem.wall_builds() - wb0;
    const long reemitted = patch ? patch->stats().reemitted - re0 : 0;
    // the bare soil: a copy of the soil now, the tires and tools lifted 10 m and stopped
    DemSystem bare(dem);
    for (int w = 0; w < soil->bin().wheels(); ++w) {
      DemWall& t = bare.mutable_wall(soil->bin().tire_wall(w));
      t.position.z() += 10.0;
      t.velocity.setZero();
      t.angular_velocity.setZero();
    }
    for (int w : {soil->bin().leveling_cylinder(), soil->bin().leveling_plate()}) {
      if (w < 0) continue;
      bare.mutable_wall(w).position.z() += 10.0;
      bare.mutable_wall(w).velocity.setZero();
    }
    const long bnb0 = bare.neighbour_builds(), bwb0 = bare.wall_builds();
    const auto tb = std::chrono::steady_clock::now();
    for (long k = 0; k < soil_steps; ++k) bare.Step();
    const double bare_wall = Seconds(tb);
    const double sim_time = s.time() - t_begin;
    const double r = bare_wall / coupled;  // (n soil_steps / coupled) / (n soil_steps / bare)
    // (a one-window level's lines are its first window's, untagged: a '#' line says so)
    const std::string tag = done == 0 && wanted == 2 ? "_before_following" : "";
    const char *lv = level.c_str(), *tg = tag.c_str();
    std::printf("# soil_scene %s_window%s: t = %.3f-%.3f s, speed %.2f m/s, %ld soil steps%s\n", lv, tg, t_begin,
                s.time(), s.vehicle().ForwardSpeed(), soil_steps,
                wanted == 1 ? " (the only window of this level: 0.2 s into the drive, before the patch follows)" : "");
    std::printf("soil_scene %s_window%s %.4f s\n", lv, tg, sim_time);
    std::printf("soil_scene %s_reemitted%s %ld count\n", lv, tg, reemitted);
    std::printf("soil_scene %s_neighbour_rebuilds%s %ld count\n", lv, tg, nb);
    std::printf("soil_scene %s_wall_rebuilds%s %ld count\n", lv, tg, wb);
    std::printf("soil_scene %s_bare_soil_neighbour_rebuilds%s %ld count\n", lv, tg, bare.neighbour_builds() - bnb0);
    std::printf("soil_scene %s_bare_soil_wall_rebuilds%s %ld count\n", lv, tg, bare.wall_builds() - bwb0);
    std::printf("soil_scene %s_coupled_rate%s %.3f Mparticle-steps/s\n", lv, tg, 1e-6 * n * soil_steps / coupled);
    std::printf("soil_scene %s_bare_soil_rate%s %.3f Mparticle-steps/s\n", lv, tg, 1e-6 * n * soil_steps / bare_wall);
    std::printf("soil_scene %s_rate_ratio%s %.3f ratio\n", lv, tg, r);
    std::printf("soil_scene %s_wall_s_per_sim_s%s %.1f s\n", lv, tg, coupled / sim_time);
    std::printf("soil_scene %s_wall_us_per_soil_step%s %.1f us\n", lv, tg, 1e6 * coupled / soil_steps);
    std::fflush(stdout);
    ratio = r;
    wall_per_sim = coupled / sim_time;
    ++done;
    at = -1;
  }
  bool StopRequested() override { return done == wanted; }
  double wall_per_sim = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: soil_scene_bench SCENE.yaml LEVEL[,LEVEL...] [window_s] [[LEVEL:]key=value ...]\n");
    return 2;
  }
  auto split = [](const std::string& text) {
    std::vector<std::string> out;
    std::stringstream ss(text);
    std::string l;
    while (std::getline(ss, l, ',')) out.push_back(l);
    return out;
  };
  const std::vector<std::string> levels = split(argv[2]);
  const char* one_env = std::getenv("DM_SOIL_ONE_WINDOW");
  const std::vector<std::string> one_window = split(one_env ? one_env : "");
  const double window = argc > 3 ? std::stod(argv[3]) : 0.05;
  // [s] the patch follows the vehicle this long before the second window
  const char* follow_env = std::getenv("DM_SOIL_FOLLOW");
  const double follow = follow_env ? std::stod(follow_env) : 0.3;
  // (LEVEL:key=value: that level's only; a ':' before the first '=' marks one)
  std::vector<std::pair<std::string, std::string>> overrides;  // (level or empty, key=value)
  for (int i = 4; i < argc; ++i) {
    const std::string a = argv[i];
    const auto colon = a.find(':'), eq = a.find('=');
    if (colon != std::string::npos && colon < eq)
      overrides.emplace_back(a.substr(0, colon), a.substr(colon + 1));
    else
      overrides.emplace_back("", a);
  }
  double ratio_sum = 0.0;
  int ratios = 0;
  for (const std::string& level : levels) {
    try {
      std::vector<std::string> o;
      for (const auto& [only, kv] : overrides)
        if (only.empty() || only == level) o.push_back(kv);
      o.push_back("terrain_overrides.fidelity=" + level);
      const bool one = std::find(one_window.begin(), one_window.end(), level) != one_window.end();
      MobilityRunParams p = MobilityRunParams::Read(YamlReader::LoadWithOverrides(argv[1], o));
      p.end_when_steady = false;
      const VehicleSpec spec = VehicleSpec::Load(p.vehicle_file);
      auto t0 = std::chrono::steady_clock::now();
      PreparationHooks hooks;  // (on stderr: the benchmark's lines stay as they are)
      hooks.progress = [&level](const PreparationProgress& at) {
        std::fprintf(stderr, "soil_scene_bench: %s: preparing: %s\n", level.c_str(), at.Line().c_str());
      };
      hooks.progress_every = 60.0;
      std::unique_ptr<TerrainModel> terrain =
          LoadTerrainModel(p.terrain_file, TerrainVehicleOf(spec), p.terrain_overrides, hooks);
      const double prepare = Seconds(t0);
      auto* soil = dynamic_cast<DemSoilTerrain*>(terrain.get());
      if (!soil) throw ConfigError(p.terrain_file + ": the soil_scene benchmark needs a dem_soil terrain");
      const int n = soil->bin().dem().num_alive();
      const DemSystem& dem0 = soil->bin().dem();
      std::printf("soil_scene %s_particles %d count\n", level.c_str(), n);
      std::printf("soil_scene %s_soil_time_step %.3g s\n", level.c_str(), dem0.dt());
      std::printf("soil_scene %s_soil_critical_time_step %.3g s\n", level.c_str(), dem0.CriticalTimeStep().dt_crit);
      std::printf("soil_scene %s_prepare_wall %.1f s\n", level.c_str(), prepare);
      std::fflush(stdout);
      // the windows of the whole coupled step (Windows)
      MobilityRun run(p, std::move(terrain));
      const VehicleCoSim& sim = run.sim();
      const SoilPatch* patch = soil->patch();
      const long window_steps = std::max(1L, std::lround(window / sim.dt()));
      Windows windows;
      windows.soil = soil;
      windows.patch = patch;
      windows.level = level;
      windows.n = n;
      windows.window_steps = window_steps;
      windows.follow = follow;
      windows.wanted = one ? 1 : 2;
      const MobilityRunResult r = run.Run(&windows);
      if (!r.error.empty()) throw SimulationError(r.error);
      if (windows.done < windows.wanted)
        throw SimulationError(detail::Concat("the run ended (status ", r.Status(), ") before its windows: ", windows.done,
                                             " of ", windows.wanted, " timed", patch && !patch->stats().following
                                                                ? " (the patch never started to follow the vehicle)"
                                                                : ""));
      std::printf("soil_scene %s_40s_run_extrapolated %.0f s\n", level.c_str(), 40.0 * windows.wall_per_sim + prepare);
      if (one) continue;  // (its window is before the patch follows: not in the mean)
      ratio_sum += windows.ratio;
      ++ratios;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "soil_scene_bench: level %s: %s\n", level.c_str(), e.what());
      return 1;
    }
  }
  if (ratios > 0) std::printf("soil_scene rate_ratio_to_bare_soil %.3f ratio\n", ratio_sum / ratios);
  return 0;
}
