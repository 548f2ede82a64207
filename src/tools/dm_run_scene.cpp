// Command-line runner of core scenes (no ROS): runs a scene file and prints its result.
//
//   dm_run_scene SCENE.yaml [key=value ...] [--out RESULT.yaml] [--history HISTORY.csv] [--quiet]
//
// key=value overrides a scene key (dotted for nested keys: driver.kp=4000, grade_deg=12).
// Arguments of the form __name:=value (added by roslaunch) are ignored.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/dem_pour.h"
#include "dem_mobility/core/scenes/road_scene.h"
#include "dem_mobility/core/scenes/uniaxial_compression.h"

using namespace dem_mobility;

namespace {
int Usage() {
  std::cerr << "usage: dm_run_scene SCENE.yaml [key=value ...] [--out RESULT.yaml] [--history HISTORY.csv] [--quiet]\n";
  return 2;
}

}  // namespace

// The soil preparation scene: pour, settle, consolidate with the lid, release.
int RunPour(const YamlReader& reader, const std::string& out_file) {
  const DemPourParams p = DemPourParams::Read(reader);
  std::printf("scene %s: %d particles of %.3g m in a %.3g x %.3g m box, dt %.3g s, %d thread(s)\n", p.file.c_str(),
              p.particles, p.soil.diameter, p.box_length, p.box_width, p.time_step, p.threads);
  std::fflush(stdout);
  const DemPourResult r = RunDemPour(p);
  if (!out_file.empty()) WriteDemPourResult(r, p, out_file);
  std::printf("poured: height %.4f m, bulk density %.1f kg/m^3\n", r.height_poured, r.density_poured);
  std::printf("lid: %.1f kPa held; released: height %.4f m, bulk density %.1f kg/m^3, mean plastic strain %.4f\n",
              r.lid_pressure_reached * 1e-3, r.height_consolidated, r.density_consolidated, r.mean_plastic_strain);
  std::printf("run: %ld steps, %.3f s simulated in %.1f s wall (%.2f M particle-steps/s)\n", r.steps, r.sim_time,
              r.wall_time, r.wall_time > 0 ? 1e-6 * r.particles * r.steps / r.wall_time : 0.0);
  if (!r.error.empty()) {
    std::cerr << "dm_run_scene: simulation error: " << r.error << "\n";
    return 3;
  }
  return 0;
}

// The cone penetrometer: preparation, then the cone driven down; prints the cone index.
int RunCone(const YamlReader& reader, const std::string& out_file, bool quiet) {
  const ConeParams p = ConeParams::Read(reader);
  std::printf("scene %s: level '%s', f %.4g, mu %.3g, %d particles of %.3g m in a %.3g m container, cone at %.3g m/s, "
              "dt %.3g s, %d thread(s)\n",
              p.file.c_str(), p.level.name.c_str(), p.cohesion_factor, p.friction, p.ParticleCount(),
              p.level.particle_diameter, p.level.container_diameter, p.level.cone_speed, p.level.time_step, p.threads);
  std::fflush(stdout);
  ConePenetrometer scene(p);
  const auto t0 = std::chrono::steady_clock::now();
  double next = 2.0;
  const ConeResult r = scene.Run(
      [&](const ConePenetrometer& c) {
        if (quiet) return;
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (wall < next) return;
        next = wall + 2.0;
        if (c.phase() == ConePenetrometer::Phase::kPenetrate && !c.samples().empty())
          std::printf("  %7.1f s wall  t = %.3f s  %-11s tip depth %.3f / %.3f m  CI %.1f psi\n", wall, c.dem().time(),
                      ConePenetrometer::PhaseName(c.phase()), c.tip_depth(), p.level.ci_to, c.samples().back().ci_psi);
        else
          std::printf("  %7.1f s wall  t = %.3f s  %-11s\n", wall, c.dem().time(), ConePenetrometer::PhaseName(c.phase()));
        std::fflush(stdout);
      },
      500);
  if (!out_file.empty()) WriteConeResult(r, p, out_file);
  std::printf("prepared: surface %.3f m, bulk density %.1f -> %.1f kg/m^3, lid %.1f kPa held\n", r.surface_height,
              r.density_poured, r.density_consolidated, r.lid_pressure_reached * 1e-3);
  std::printf("cone_index: %.2f psi (std %.2f, trend %.1f psi/m over tip depths %.3g-%.3g m, %d samples); cone speed "
              "%.4f-%.4f m/s\n",
              r.ci_psi, r.ci_std_psi, r.ci_trend_psi_per_m, p.level.ci_from, p.level.ci_to, r.window_samples,
              r.speed_min, r.speed_max);
  std::printf("run: %ld steps, %.3f s simulated (%.3f s preparation) in %.1f s wall\n", r.steps, r.sim_time,
              r.prep_time, r.wall_time);
  if (!r.error.empty()) {
    std::cerr << "dm_run_scene: simulation error: " << r.error << "\n";
    if (!out_file.empty()) std::cerr << "dm_run_scene: the results so far are in " << out_file << "\n";
    return 3;
  }
  return 0;
}

// The piston-cylinder compression: bulk density against pressure, loading and unloading.
int RunCompression(const YamlReader& reader, const std::string& out_file) {
  const CompressionParams p = CompressionParams::Read(reader);
  std::printf("scene %s: %.3g m particles in a %.3g m cylinder, f %.3g, dt %.3g s\n", p.file.c_str(),
              p.particle_diameter, p.cylinder_diameter, p.soil.cohesion_factor, p.time_step);
  std::fflush(stdout);
  const CompressionResult r = RunUniaxialCompression(p);
  if (!out_file.empty()) WriteCompressionResult(r, p, out_file);
  std::printf("poured: %.1f kg/m^3 (%d particles)\n", r.density_poured, r.particles);
  for (const CompressionPoint& c : r.loading) std::printf("  loading   %8.1f kPa  %7.1f kg/m^3\n", c.pressure * 1e-3, c.density);
  for (const CompressionPoint& c : r.unloading) std::printf("  unloading %8.1f kPa  %7.1f kg/m^3\n", c.pressure * 1e-3, c.density);
  std::printf("released: %.1f kg/m^3; %.3f s simulated in %.1f s wall\n", r.density_released, r.sim_time, r.wall_time);
  if (!r.error.empty()) {
    std::cerr << "dm_run_scene: simulation error: " << r.error << "\n";
    return 3;
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 2) return Usage();
  std::string scene_file = argv[1], out_file, history_file;
  bool quiet = false;
  std::vector<std::string> overrides;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) out_file = argv[++i];
    else if (a == "--history" && i + 1 < argc) history_file = argv[++i];
    else if (a == "--quiet") quiet = true;
    else if (a.rfind("__", 0) == 0 && a.find(":=") != std::string::npos) continue;  // roslaunch's __name:=, __log:=
    else if (a.find('=') != std::string::npos && a.rfind("--", 0) != 0) overrides.push_back(a);
    else return Usage();
  }
  RoadSceneParams params;
  std::unique_ptr<RoadScene> scene;
  try {
    const YamlReader reader = YamlReader::LoadWithOverrides(scene_file, overrides);
    // make sure the results can be written before spending the run on them
    for (const std::string& f : {out_file, history_file}) {
      if (f.empty()) continue;
      const std::filesystem::path parent = std::filesystem::path(f).parent_path();
      std::error_code ec;
      if (!parent.empty()) std::filesystem::create_directories(parent, ec);
      if (!std::ofstream(f, std::ios::app)) throw ConfigError(f + ": cannot write the result file here");
    }
    const std::string kind = reader.Has("scene") ? reader.String("scene") : "";
    if (kind == "dem_pour") return RunPour(reader, out_file);
    if (kind == "cone_penetrometer") return RunCone(reader, out_file, quiet);
    if (kind == "uniaxial_compression") return RunCompression(reader, out_file);
    params = RoadSceneParams::Read(reader);
    scene = std::make_unique<RoadScene>(params);
  } catch (const ConfigError& e) {
    std::cerr << "dm_run_scene: error: " << e.what() << "\n";
    return 1;
  }
  const TimeStepLimit& lim = scene->sim().limit();
  std::printf("scene %s: grade %.1f deg, %d bodies, dt %.3g s (critical %.3g s, %s), %.1f s simulated\n",
              scene_file.c_str(), params.grade_deg, scene->vehicle().system().num_bodies() - 1, scene->dt(),
              lim.dt_crit, lim.element.c_str(), params.duration);
  std::fflush(stdout);
  // progress on the console about once a second of wall time
  class Progress final : public CoSimObserver {
   public:
    explicit Progress(double duration) : duration_(duration) {}
    void OnStep(const VehicleCoSim& sim, const DriveCommand&) override {
      if ((sim.step() & 255) != 0) return;
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
      if (wall < next_) return;
      next_ += 1.0;
      const double t = std::max(0.0, sim.driver_time()), rtf = sim.time() / wall;
      std::printf("  t = %6.2f / %.0f s  speed %6.2f m/s  real-time factor %.2f  ETA %.0f s\n", t, duration_,
                  sim.vehicle().ForwardSpeed(), rtf, (duration_ - t) / std::max(rtf, 1e-9));
      std::fflush(stdout);
    }

   private:
    double duration_, next_ = 1.0;
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  } progress(params.duration);
  const RoadResult r = scene->Run(quiet ? nullptr : &progress);
  try {
    if (!out_file.empty()) WriteRoadResult(r, params, out_file);
    if (!history_file.empty()) WriteRoadHistory(r, history_file);
  } catch (const ConfigError& e) {
    std::cerr << "dm_run_scene: error: " << e.what() << "\n";
    return 1;
  }
  std::printf("speed_made_good: %.3f m/s (%.2f mph), status %s, window slope %.4f m/s^2\n", r.smg.value,
              r.smg.value / 0.44704, r.smg.status.c_str(), r.smg.window_slope);
  std::printf("run: %ld steps, %.2f s simulated in %.2f s wall (real-time factor %.2f)\n", r.steps, r.sim_time,
              r.wall_time, r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0);
  if (!r.error.empty()) {
    std::cerr << "dm_run_scene: simulation error: " << r.error << "\n";
    if (!out_file.empty()) std::cerr << "dm_run_scene: the results so far are in " << out_file << "\n";
    return 3;
  }
  return 0;
}
