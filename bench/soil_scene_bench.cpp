// soil_scene: the vehicle on the moving soil patch, per fidelity level. For each level: the soil
// prepared (its wall time), the vehicle settled and driving, then a timed window of the whole
// coupled step (vehicle, tires, patch emission and leveling, soil); wall seconds per simulated
// second, and particle-steps per second of the coupled step against the bare soil patch (the same
// soil, in the same state, with the tires lifted clear and no patch) over the same steps.
//   soil_scene_bench SCENE.yaml LEVEL[,LEVEL...] [window_s] [key=value ...]
#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/cosim/cosim_loop.h"
#include "dem_mobility/core/mobility/mobility_scene.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

using namespace dem_mobility::core;

namespace {
double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Stops the run `after` simulated seconds of driving.
class StopAfter final : public CoSimObserver {
 public:
  explicit StopAfter(double after) : after_(after) {}
  void OnStep(const VehicleCoSim& sim, const DriverCommand&) override { t_ = sim.driver_time(); }
  bool StopRequested() override { return t_ >= after_; }

 private:
  double after_, t_ = -1.0;
};
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: soil_scene_bench SCENE.yaml LEVEL[,LEVEL...] [window_s] [key=value ...]\n");
    return 2;
  }
  std::vector<std::string> levels;
  {
    std::stringstream ss(argv[2]);
    std::string l;
    while (std::getline(ss, l, ',')) levels.push_back(l);
  }
  const double window = argc > 3 ? std::stod(argv[3]) : 0.05;
  std::vector<std::string> overrides;
  for (int i = 4; i < argc; ++i) overrides.push_back(argv[i]);
  double ratio_sum = 0.0;
  int ratios = 0;
  for (const std::string& level : levels) {
    try {
      std::vector<std::string> o = overrides;
      o.push_back("terrain_overrides.fidelity=" + level);
      MobilityRunParams p = MobilityRunParams::Read(YamlReader::LoadWithOverrides(argv[1], o));
      p.end_when_steady = false;
      const VehicleSpec spec = VehicleSpec::Load(p.vehicle_file);
      auto t0 = std::chrono::steady_clock::now();
      std::unique_ptr<TerrainModel> terrain = LoadTerrainModel(p.terrain_file, TerrainVehicleOf(spec), p.terrain_overrides);
      const double prepare = Seconds(t0);
      auto* soil = dynamic_cast<DemSoilTerrain*>(terrain.get());
      if (!soil) throw ConfigError(p.terrain_file + ": the soil_scene benchmark needs a dem_soil terrain");
      const int n = soil->bin().dem().num_alive();
      std::printf("soil_scene %s_particles %d count\n", level.c_str(), n);
      std::printf("soil_scene %s_prepare_wall %.1f s\n", level.c_str(), prepare);
      std::fflush(stdout);
      // settle and drive 0.2 s (the wheels rolling, the patch in place), then the timed window
      MobilityRun run(p, std::move(terrain));
      StopAfter warm(0.2);
      MobilityRunResult r = run.Run(&warm);
      if (!r.error.empty()) throw SimulationError(r.error);
      VehicleCoSim& sim = run.sim();
      const long steps = std::max(1L, std::lround(window / sim.dt()));
      const long soil0 = soil->bin().dem().step_count();
      t0 = std::chrono::steady_clock::now();
      for (long k = 0; k < steps; ++k) sim.Step(run.terrain_port());
      const double coupled = Seconds(t0);
      const long soil_steps = soil->bin().dem().step_count() - soil0;
      // the bare soil: a copy of the soil now, the tires lifted 10 m and stopped
      DemSystem bare(soil->bin().dem());
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
      t0 = std::chrono::steady_clock::now();
      for (long k = 0; k < soil_steps; ++k) bare.Step();
      const double bare_wall = Seconds(t0);
      const double sim_time = steps * sim.dt();
      const double ratio = (static_cast<double>(n) * soil_steps / coupled) / (static_cast<double>(n) * soil_steps / bare_wall);
      std::printf("soil_scene %s_window %.4f s_simulated\n", level.c_str(), sim_time);
      std::printf("soil_scene %s_coupled_rate %.3f Mparticle-steps/s\n", level.c_str(), 1e-6 * n * soil_steps / coupled);
      std::printf("soil_scene %s_bare_soil_rate %.3f Mparticle-steps/s\n", level.c_str(), 1e-6 * n * soil_steps / bare_wall);
      std::printf("soil_scene %s_rate_ratio %.3f ratio\n", level.c_str(), ratio);
      std::printf("soil_scene %s_wall_s_per_sim_s %.1f s\n", level.c_str(), coupled / sim_time);
      std::printf("soil_scene %s_40s_run_extrapolated %.0f s\n", level.c_str(), 40.0 * coupled / sim_time + prepare);
      std::fflush(stdout);
      ratio_sum += ratio;
      ++ratios;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "soil_scene_bench: level %s: %s\n", level.c_str(), e.what());
      return 1;
    }
  }
  std::printf("soil_scene rate_ratio_to_bare_soil %.3f ratio\n", ratio_sum / ratios);
  return 0;
}
