// dem_step: particle-steps per second of the DEM solver on the reference bed of
// ../shared/bench/lammps-bed.in (124,800 particles of 3 cm, fcc with nearest neighbours 1 %
// overlapped, gravity, a floor), with contact history, adhesion and plasticity on (the nominal
// soil), at 1 and 2 threads. The LAMMPS bed has periodic sides; ours has four side walls.
//   dem_step_bench [SOIL.yaml] [steps]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"

using namespace dem_mobility;
using Eigen::Vector3d;

namespace {
struct Figures {
  double rate, bytes_per_particle;
  int particles, contacts;
};

Figures Run(const SoilParams& soil, int threads, int steps) {
  DemSettings st;
  st.threads = threads;
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
  for (int i = 0; i < 200; ++i) s.Step();  // as the LAMMPS input: 200 steps, then the timed 1000
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s.Step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Figures f;
  f.particles = s.size();
  f.contacts = s.contacts();
  f.rate = static_cast<double>(s.size()) * steps / wall;
  f.bytes_per_particle = static_cast<double>(s.MemoryBytes()) / s.size();
  return f;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string file = argc > 1 ? argv[1] : DM_CONFIG_DIR "/soils/nominal_clay.yaml";
  const int steps = argc > 2 ? std::stoi(argv[2]) : 1000;
  const SoilParams soil = SoilParams::Read(YamlReader::Load(file));
  const Figures one = Run(soil, 1, steps);
  std::printf("dem_step bed_particles %d count\n", one.particles);
  std::printf("dem_step bed_contacts %d count\n", one.contacts);
  std::printf("dem_step bed_rate_1thread %.3f Mparticle-steps/s\n", one.rate * 1e-6);
  const Figures two = Run(soil, 2, steps);
  std::printf("dem_step bed_rate_2threads %.3f Mparticle-steps/s\n", two.rate * 1e-6);
  std::printf("dem_step bed_speedup_1_to_2 %.3f x\n", two.rate / one.rate);
  std::printf("dem_step bed_bytes_per_particle %.0f B\n", two.bytes_per_particle);
  std::fflush(stdout);
  return 0;
}
