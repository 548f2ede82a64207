// wheel_soil: particle-steps per second of the single-wheel rig (a tire of 8,928 triangles driven at
// 20 % slip through a prepared soil bin) at 1 and 2 threads, beside the same soil, in the same
// state, with the tire lifted clear of it: the tire's cost as a share of the soil step. Each rate
// is the best of DM_BENCH_REPEATS timings (default 3; the rig, the bare soil and the bare soil
// without the plastic ledger alternated), as dem_step's are: on this VM one timing can run a
// quarter slower than the next, and a ratio of two single timings moved with it.
//   wheel_soil_bench SCENE.yaml [steps] [key=value ...]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_repeats.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/scenes/single_wheel.h"

using namespace dem_mobility::core;
using Eigen::Vector3d;

namespace {
double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// particle-steps per second of a copy of the rig over `steps` steps, after 50 warm-up steps
double RigRate(const SingleWheelRig& rig0, int threads, int steps, double* contacts) {
  SingleWheelRig rig(rig0);
  rig.set_threads(threads);
  for (int i = 0; i < 50; ++i) rig.Step();
  double c = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) {
    rig.Step();
    c += rig.wrench().contacts;
  }
  const double wall = Seconds(t0);
  *contacts = c / steps;
  return static_cast<double>(rig.dem().num_alive()) * steps / wall;
}

// the same soil without the tire: the rig's DEM copied, the tire lifted 10 m and stopped
double BareRate(const SingleWheelRig& rig0, int threads, int steps, bool plastic_ledger = true) {
  DemSystem s(rig0.dem());
  if (!plastic_ledger) s.set_plastic_ledger(false);  // (the rig's run keeps it: the soil's energy ledger)
  DemWall& t = s.mutable_wall(rig0.bin().tire_wall(0));
  t.position.z() += 10.0;
  t.velocity.setZero();
  t.angular_velocity.setZero();
  s.set_threads(threads);
  for (int i = 0; i < 50; ++i) s.Step();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s.Step();
  return static_cast<double>(s.num_alive()) * steps / Seconds(t0);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: wheel_soil_bench SCENE.yaml [steps] [key=value ...]\n");
    return 2;
  }
  const int steps = argc > 2 ? std::stoi(argv[2]) : 2000;
  const int repeats = dem_mobility::bench::Repeats("wheel_soil_bench");  // (before the set-up: minutes)
  std::vector<std::string> overrides;
  for (int i = 3; i < argc; ++i) overrides.push_back(argv[i]);
  const SingleWheelParams p = SingleWheelParams::Read(YamlReader::LoadWithOverrides(argv[1], overrides));
  // the rig to steady rolling (0.3 m of travel), at the scene's threads
  SingleWheelRig rig(p);
  const auto t0 = std::chrono::steady_clock::now();
  while (!rig.done() && !(rig.driving() && rig.travel() >= 0.3)) rig.Step();
  if (rig.done()) {
    std::fprintf(stderr, "wheel_soil_bench: the rig ended before the wheel rolled (%s)\n", rig.phase().c_str());
    return 1;
  }
  const double setup = Seconds(t0);
  const int n = rig.dem().num_alive();
  std::printf("# wheel_soil level %s\n", p.bin.level.name.c_str());
  std::printf("wheel_soil particles %d count\n", n);
  std::printf("wheel_soil tire_triangles %zu count\n", p.tire.soil_mesh.faces.size());
  std::printf("wheel_soil setup_wall %.1f s\n", setup);
  std::fflush(stdout);
  double rig_rate[3] = {0, 0, 0}, bare_rate[3] = {0, 0, 0}, contacts = 0.0;
  for (int T : {1, 2}) {
    double unledgered = 0.0;
    for (int r = 0; r < repeats; ++r) {
      bare_rate[T] = std::max(bare_rate[T], BareRate(rig, T, steps));
      rig_rate[T] = std::max(rig_rate[T], RigRate(rig, T, steps, &contacts));
      // the soil's plastic ledger (a pass over the pairs of every particle whose plastic
      // deformation changed, after every step; on in every run that follows its energy): its cost
      // on the bare soil
      unledgered = std::max(unledgered, BareRate(rig, T, steps, false));
    }
    std::printf("wheel_soil rig_rate_%dthread%s %.3f Mparticle-steps/s\n", T, T > 1 ? "s" : "", 1e-6 * rig_rate[T]);
    std::printf("wheel_soil bare_soil_rate_%dthread%s %.3f Mparticle-steps/s\n", T, T > 1 ? "s" : "", 1e-6 * bare_rate[T]);
    std::printf("wheel_soil rate_ratio_%dthread%s %.3f ratio\n", T, T > 1 ? "s" : "", rig_rate[T] / bare_rate[T]);
    std::printf("wheel_soil bare_soil_rate_without_plastic_ledger_%dthread%s %.3f Mparticle-steps/s\n", T,
                T > 1 ? "s" : "", 1e-6 * unledgered);
    std::printf("wheel_soil plastic_ledger_share_%dthread%s %.3f ratio\n", T, T > 1 ? "s" : "",
                1.0 - bare_rate[T] / unledgered);
    std::fflush(stdout);
  }
  std::printf("wheel_soil tire_contacts_mean %.1f count\n", contacts);
  std::printf("wheel_soil tire_candidates %ld count\n", rig.dem().wall_candidates());
  std::printf("wheel_soil rate_ratio_to_bare_soil %.3f ratio\n", rig_rate[2] / bare_rate[2]);
  return 0;
}
