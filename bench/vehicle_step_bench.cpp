// vehicle_step: wall time of one explicit step of the 33-body vehicle on the rigid road (the
// vehicle's step plus the terrain's tire contact, called in-process), one thread, with the vehicle
// driving (tires rolling, driveline loaded). Timed runner: the median of several repetitions, each
// of many steps.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_run.h"

using namespace dem_mobility::core;

namespace {
struct Figures {
  double us_per_step, dt;
  int contacts;
};

Figures Measure(double dt) {
  MobilityRunParams p = MobilityRunParams::Read(YamlReader::Load(DM_CONFIG_DIR "/scenes/road_slope.yaml"));
  p.grade_deg = 0.0;
  p.time_step = dt;
  MobilityRun scene(p);
  Vehicle& v = scene.vehicle();
  MultibodySystem& sys = v.system();
  VehicleCoSim& sim = scene.sim();
  TerrainPort& road = scene.terrain_port();
  // roll at a steady moderate drive torque for 2 s so that the measured steps are typical
  v.SetDriveTorqueRequest(1500.0);
  while (sys.time() < 2.0) sim.Step(road);
  const long n = std::max(2000L, static_cast<long>(0.3 / scene.dt()));
  std::vector<double> reps;
  for (int r = 0; r < 7; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < n; ++i) sim.Step(road);
    reps.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / n);
  }
  std::sort(reps.begin(), reps.end());
  int contacts = 0;
  for (int i = 0; i < 4; ++i) contacts += v.wheel_wrench(i).contacts;
  return {reps[reps.size() / 2], scene.dt(), contacts};
}
}  // namespace

int main() {
  const Figures soil = Measure(1.5e-5);
  std::printf("vehicle_step time_per_step_dt_1.5e-5 %.3f us\n", soil.us_per_step);
  // (40 s worth of the timed steps: an extrapolation from the time per step, named so)
  std::printf("vehicle_step road_40s_wall_extrapolated_at_dt_1.5e-5 %.2f s\n", 40.0 / soil.dt * soil.us_per_step * 1e-6);
  std::printf("vehicle_step real_time_factor_at_dt_1.5e-5 %.3f x\n", soil.dt / (soil.us_per_step * 1e-6));
  std::printf("vehicle_step tire_vertices_in_contact %d count\n", soil.contacts);
  const Figures road = Measure(0.0);  // the road scene's own step (guard x safety)
  std::printf("vehicle_step road_scene_dt %.3g s\n", road.dt);
  std::printf("vehicle_step time_per_step_road_dt %.3f us\n", road.us_per_step);
  std::printf("vehicle_step road_40s_wall_extrapolated_at_road_dt %.2f s\n", 40.0 / road.dt * road.us_per_step * 1e-6);
  return 0;
}
