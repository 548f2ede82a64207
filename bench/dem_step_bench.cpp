// dem_step: particle-steps per second of the DEM solver at 1 and 2 threads, with contact history,
// adhesion and plasticity on (the nominal soil), on
//  (a) the reference bed of ../shared/bench/lammps-bed.in (124,800 particles of 3 cm, fcc with
//      nearest neighbours 1 % overlapped, gravity, a floor; the LAMMPS bed has periodic sides,
//      ours four side walls), and
//  (b) a poured, consolidated cohesive bed of 100,000 particles (config/scenes/dem_bench_bed.yaml,
//      prepared by the dem_pour scene first; its preparation is timed too).
//   dem_step_bench [SOIL.yaml] [steps] [BED_B_SCENE.yaml | none]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/scenes/dem_pour.h"

using namespace dem_mobility::core;
using Eigen::Vector3d;

namespace {
// bed (a), finalized and run the 200 steps the LAMMPS input runs before its timed 1000
DemSystem ReferenceBed(const SoilParams& soil) {
  DemSettings st;
  st.threads = 2;
  DemSystem s(soil, st);
  const double a = 0.042;  // fcc lattice constant: nearest neighbours at a / sqrt(2) = 0.0297 m
  const int nx = 60, ny = 40;
  const double lx = nx * a, ly = ny * a, lz = 14 * a;
  s.AddWall(MakeQuadWall("floor", {0, 0, 0}, {lx, 0, 0}, {0, ly, 0}));
  s.AddWall(MakeQuadWall("x0", {0, 0, 0}, {0, 0, lz}, {0, ly, 0}));
  s.AddWall(MakeQuadWall("x1", {lx, 0, 0}, {0, ly, 0}, {0, 0, lz}));
  s.AddWall(MakeQuadWall("y0", {0, 0, 0}, {lx, 0, 0}, {0, 0, lz}));
  s.AddWall(MakeQuadWall("y1", {0, ly, 0}, {0, 0, lz}, {lx, 0, 0}));
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int k = 0; k < 14; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& b : basis) {
          const Vector3d x((i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a);
          // the LAMMPS fill region: 0.1 to 13 lattice units high; and clear of our side walls
          if (x.z() < 0.1 * a || x.z() > 13 * a || x.x() < 0.5 * soil.diameter || x.y() < 0.5 * soil.diameter) continue;
          s.AddParticle(x);
        }
  s.Finalize(1.5e-5);
  for (int i = 0; i < 200; ++i) s.Step();
  return s;
}

// particle-steps per second over `steps` timed steps of a copy of `s`, after 20 more warm-up steps
double Rate(DemSystem s, int threads, int steps) {
  s.set_threads(threads);
  for (int i = 0; i < 20; ++i) s.Step();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s.Step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return static_cast<double>(s.num_alive()) * steps / wall;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string file = argc > 1 ? argv[1] : DM_CONFIG_DIR "/soils/nominal_clay.yaml";
  const int steps = argc > 2 ? std::stoi(argv[2]) : 1000;
  const SoilParams soil = SoilParams::Read(YamlReader::Load(file));
  const DemSystem bed_a = ReferenceBed(soil);
  std::printf("dem_step bed_particles %d count\n", bed_a.num_alive());
  std::printf("dem_step bed_contacts %d count\n", bed_a.contacts());
  const double a1 = Rate(bed_a, 1, steps), a2 = Rate(bed_a, 2, steps);
  std::printf("dem_step bed_rate_1thread %.3f Mparticle-steps/s\n", a1 * 1e-6);
  std::printf("dem_step bed_rate_2threads %.3f Mparticle-steps/s\n", a2 * 1e-6);
  std::printf("dem_step bed_speedup_1_to_2 %.3f x\n", a2 / a1);
  std::printf("dem_step bed_bytes_per_particle %.0f B\n", static_cast<double>(bed_a.MemoryBytes()) / bed_a.num_alive());
  std::fflush(stdout);
  const std::string bed_b = argc > 3 ? argv[3] : DM_CONFIG_DIR "/scenes/dem_bench_bed.yaml";
  if (bed_b == "none") return 0;
  const DemPourParams pp = DemPourParams::Read(YamlReader::Load(bed_b));
  std::unique_ptr<DemSystem> bed;
  const DemPourResult prep = RunDemPour(pp, &bed);
  if (!prep.error.empty()) {
    std::fprintf(stderr, "dem_step: preparing bed (b) failed: %s\n", prep.error.c_str());
    return 1;
  }
  std::printf("dem_step poured_particles %d count\n", bed->num_alive());
  std::printf("dem_step poured_preparation %.1f s (%.3f s simulated)\n", prep.wall_time, prep.sim_time);
  std::printf("dem_step poured_density %.0f kg/m^3\n", prep.density_consolidated);
  std::printf("dem_step poured_contacts_per_particle %.2f count\n", 2.0 * bed->contacts() / bed->num_alive());
  const double p1 = Rate(*bed, 1, steps), p2 = Rate(*bed, 2, steps);
  std::printf("dem_step poured_rate_1thread %.3f Mparticle-steps/s\n", p1 * 1e-6);
  std::printf("dem_step poured_rate_2threads %.3f Mparticle-steps/s\n", p2 * 1e-6);
  std::printf("dem_step poured_speedup_1_to_2 %.3f x\n", p2 / p1);
  std::printf("dem_step poured_bytes_per_particle %.0f B\n", static_cast<double>(bed->MemoryBytes()) / bed->num_alive());
  return 0;
}
