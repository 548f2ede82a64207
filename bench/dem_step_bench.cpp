// dem_step: particle-steps per second of the DEM solver at 1 and 2 threads, with contact history,
// adhesion and plasticity on (the nominal soil), on
//  (a) the reference bed of ../shared/bench/lammps-bed.in (124,800 particles of 3 cm, fcc with
//      nearest neighbours 1 % overlapped, gravity, a floor; the LAMMPS bed has periodic sides,
//      ours four side walls), and
//  (b) a poured, consolidated cohesive bed of 100,000 particles (config/scenes/dem_bench_bed.yaml,
//      prepared by the dem_pour scene first; its preparation is timed too).
// Per bed: the rates of the default pair kernel (the vector one, on the best instruction set the CPU
// has) and of the scalar reference (1 and 2 threads alternated, the best of DM_BENCH_REPEATS
// timings each, default 3), the neighbour builds in the timed steps, and the contacts'
// mean normal force and its parts (so that a reader sees what work the bed does); and the roofline
// of the step's two streaming passes (they alone on a copy of the bed's particles: their rates,
// their bandwidth beside the triad's, their share of the step, and the rest's scaling).
//   dem_step_bench [SOIL.yaml] [steps] [BED_B_SCENE.yaml | none]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_repeats.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/dem/dem_watchdogs.h"
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

struct Timed {
  double rate = 0.0;   // particle-steps per second
  long rebuilds = 0;   // neighbour-list builds in the timed steps
};

// particle-steps per second over `steps` timed steps of a copy of `s` on `kernel`, after 20 more
// warm-up steps
Timed Rate(DemSystem s, int threads, int steps, PairKernel kernel = PairKernel::kAuto) {
  s.set_threads(threads);
  s.set_pair_kernel(kernel);
  for (int i = 0; i < 20; ++i) s.Step();
  const long builds0 = s.neighbour_builds();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) s.Step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return Timed{static_cast<double>(s.num_alive()) * steps / wall, s.neighbour_builds() - builds0};
}

// The memory ceiling of the roofline: a STREAM-style triad a = b + s c over three arrays of 2^25
// doubles (768 MB in all, far beyond the caches) on `threads` threads, best of 5, in GB/s (24 bytes
// moved per element: two reads and a write; the write-allocate read not counted, as STREAM does).
double TriadBandwidth(int threads) {
  const long n = 1L << 25;
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  double best = 0.0;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, 24.0 * n / wall * 1e-9);
  }
  if (!(a[n / 2] == 7.0)) std::printf("dem_step triad: wrong result\n");
  return best;
}

// The step's two streaming passes alone: DemSystem::Step without the force evaluation between
// them, `steps` times on a copy of the bed's particle arrays, on `threads` threads. The drift, the
// state watchdog and the hot records packed; then the sums unpacked and started again, the overlap
// watchdog, the second half kick and the plastic update's inputs read (its law left out: a few
// flops and a table lookup). The same store methods on the same arrays as the step's own passes,
// so the same memory traffic; particle-steps per second. (Without the sweep, f is the weight at
// every step: the particles fall freely, far less than the watchdog's half skin in these steps.)
volatile double g_streaming_sink = 0.0;
double StreamingRate(const DemSystem& s, int threads, int steps) {
  ParticleStore ps = s.particles();
  ps.SizeScratch();
  const int n = ps.slots();
  const double dt = s.dt(), h = 0.5 * dt, inv_m = 1.0 / s.mass();
  const double half_skin = 0.05 * s.soil().diameter, overlap_limit = 0.5 * s.soil().diameter;
  const Vector3d weight = s.mass() * s.gravity();
  for (int i = 0; i < n; ++i) ps.PackFresh(i, ps.live(i) ? weight : Vector3d::Zero());
  double check = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int step = 0; step < steps; ++step) {
    double max_disp2 = 0.0, sum = 0.0;
    int tripped = n;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(max : max_disp2) reduction(min : tripped)
    for (int i = 0; i < n; ++i) {
      if (!ps.live(i)) continue;
      if (!ps.held[i]) {
        ps.v[i] += h * inv_m * ps.f[i];
        ps.x[i] += dt * ps.v[i];
        max_disp2 = std::max(max_disp2, (ps.x[i] - ps.x_built[i]).squaredNorm());
      }
      if (StateTrips(ps, i, dt, half_skin)) tripped = std::min(tripped, i);
      ps.PackHot(i);
    }
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : tripped) reduction(+ : sum)
    for (int i = 0; i < n; ++i) {
      ps.Unpack(i);
      if (!ps.live(i)) {
        ps.StartSums(i, Vector3d::Zero());
        continue;
      }
      ps.StartSums(i, weight);
      if (OverlapTrips(ps, i, overlap_limit)) tripped = std::min(tripped, i);
      if (!ps.held[i]) ps.v[i] += h * inv_m * ps.f[i];
      sum += ps.plastic[i] * ps.max_repulsion[i] + ps.adhesion_max[i] * ps.normal_sum[i] + ps.adhesion_reach[i];
    }
    check += max_disp2 + sum + tripped;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  g_streaming_sink = check;
  return static_cast<double>(s.num_alive()) * steps / wall;
}

// The bytes those two passes move per particle, counted as STREAM counts them (each array a pass
// reads once, each it writes once; the write-allocate reads not counted): the drift reads x, v, f,
// x_built, the state, the held flag, the plastic deformation and the adhesion, and writes x, v and
// the hot record; the unpack reads the sums, the state, the held flag, v, the plastic deformation
// and the adhesion, and writes f, the three maxima, the sums and v.
constexpr int kDriftBytes = 4 * sizeof(Vector3d) + sizeof(SlotState) + sizeof(unsigned char) + 2 * sizeof(double) +
                            2 * sizeof(Vector3d) + sizeof(HotParticle);
constexpr int kUnpackBytes = sizeof(PairSums) + sizeof(SlotState) + sizeof(unsigned char) + sizeof(Vector3d) +
                             2 * sizeof(double) + sizeof(Vector3d) + 3 * sizeof(double) + sizeof(PairSums) +
                             sizeof(Vector3d);
constexpr int kStreamingBytes = kDriftBytes + kUnpackBytes;

// The rates of `kernel` at 1 and 2 threads, alternated, the best of `repeats` timings each (this
// VM's rates move by up to a third between runs minutes apart: the best is the least disturbed;
// bench.sh times LAMMPS the same way)
void BestRates(const DemSystem& s, int steps, int repeats, PairKernel kernel, Timed* r1, Timed* r2) {
  *r1 = *r2 = Timed{};
  for (int r = 0; r < repeats; ++r) {
    const Timed a = Rate(s, 1, steps, kernel), b = Rate(s, 2, steps, kernel);
    if (a.rate > r1->rate) *r1 = a;
    if (b.rate > r2->rate) *r2 = b;
  }
}

// The rates of the default (vector) kernel and of the scalar reference at 1 and 2 threads, the
// rebuilds in the timed steps and the contacts at the end of the warm-up: the lines of one bed.
void Report(const char* bed, const DemSystem& s, int steps) {
  const int repeats = dem_mobility::bench::Repeats("dem_step_bench");
  DemSystem warm = s;
  for (int i = 0; i < 20; ++i) warm.Step();
  const DemContactSummary c = warm.ContactSummary();
  std::printf("# dem_step %s: pair kernel %s\n", bed, PairKernelName(PairKernel::kAuto));
  std::printf("dem_step %s_contacts_per_particle %.2f count\n", bed, 2.0 * c.contacts / s.num_alive());
  std::printf("dem_step %s_mean_normal_force %.4g N\n", bed, c.mean_normal);
  std::printf("dem_step %s_mean_adhesion %.4g N\n", bed, c.mean_adhesion);
  std::printf("dem_step %s_mean_repulsion %.4g N\n", bed, c.mean_repulsion);
  std::printf("dem_step %s_adhesive_contact_fraction %.3f ratio\n", bed, c.adhesive_fraction);
  std::fflush(stdout);
  Timed v1, v2, s1, s2;
  BestRates(s, steps, repeats, PairKernel::kAuto, &v1, &v2);
  // DM_DEM_BENCH_VECTOR_ONLY=1: the default kernel alone (for a profile of it)
  const char* only = std::getenv("DM_DEM_BENCH_VECTOR_ONLY");
  const bool scalar = !(only && std::string(only) == "1");
  if (scalar) BestRates(s, steps, repeats, PairKernel::kScalar, &s1, &s2);
  std::printf("# dem_step %s_rate: the best of %d timings at each thread count, alternated (the scalar kernel's too)\n", bed, repeats);
  std::printf("dem_step %s_rate_1thread %.3f Mparticle-steps/s\n", bed, v1.rate * 1e-6);
  std::printf("dem_step %s_rate_2threads %.3f Mparticle-steps/s\n", bed, v2.rate * 1e-6);
  std::printf("dem_step %s_speedup_1_to_2 %.3f x\n", bed, v2.rate / v1.rate);
  std::printf("# dem_step %s_rebuilds: the neighbour-list builds of the %d timed steps\n", bed, steps);
  std::printf("dem_step %s_rebuilds %ld count\n", bed, v2.rebuilds);
  if (scalar) {
    std::printf("dem_step %s_scalar_rate_1thread %.3f Mparticle-steps/s\n", bed, s1.rate * 1e-6);
    std::printf("dem_step %s_scalar_rate_2threads %.3f Mparticle-steps/s\n", bed, s2.rate * 1e-6);
    std::printf("dem_step %s_vector_over_scalar_2threads %.3f x\n", bed, v2.rate / s2.rate);
  }
  std::printf("dem_step %s_bytes_per_particle %.0f B\n", bed, static_cast<double>(s.MemoryBytes()) / s.num_alive());
  std::fflush(stdout);
  // the roofline of the step's streaming passes: they alone, at 1 and 2 threads (alternated, the
  // best of the repeats), their bandwidth beside the triad's, and what is left of the step without them
  double p1 = 0.0, p2 = 0.0;
  for (int r = 0; r < repeats; ++r) {
    p1 = std::max(p1, StreamingRate(s, 1, steps));
    p2 = std::max(p2, StreamingRate(s, 2, steps));
  }
  std::printf("# dem_step %s_streaming: the step's two passes over the particles alone (no forces), %d steps, best of %d\n", bed, steps, repeats);
  std::printf("dem_step %s_streaming_rate_1thread %.3f Mparticle-steps/s\n", bed, p1 * 1e-6);
  std::printf("dem_step %s_streaming_rate_2threads %.3f Mparticle-steps/s\n", bed, p2 * 1e-6);
  std::printf("dem_step %s_streaming_speedup_1_to_2 %.3f x\n", bed, p2 / p1);
  std::printf("dem_step %s_streaming_bytes_per_particle_step %d B\n", bed, kStreamingBytes);
  std::printf("dem_step %s_streaming_bandwidth_1thread %.1f GB/s\n", bed, p1 * kStreamingBytes * 1e-9);
  std::printf("dem_step %s_streaming_bandwidth_2threads %.1f GB/s\n", bed, p2 * kStreamingBytes * 1e-9);
  std::printf("# dem_step %s_streaming_share: the passes' time over the whole step's, at each thread count\n", bed);
  std::printf("dem_step %s_streaming_share_1thread %.3f ratio\n", bed, v1.rate / p1);
  std::printf("dem_step %s_streaming_share_2threads %.3f ratio\n", bed, v2.rate / p2);
  // the rest of the step (the sweep, the walls, the builds): its time at 1 thread over its time at 2
  const double rest1 = 1.0 / v1.rate - 1.0 / p1, rest2 = 1.0 / v2.rate - 1.0 / p2;
  if (rest1 > 0.0 && rest2 > 0.0) std::printf("dem_step %s_rest_speedup_1_to_2 %.3f x\n", bed, rest1 / rest2);
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  const std::string file = argc > 1 ? argv[1] : DM_CONFIG_DIR "/soils/nominal_clay.yaml";
  const int steps = argc > 2 ? std::stoi(argv[2]) : 1000;
  const SoilParams soil = SoilParams::Read(YamlReader::Load(file));
  std::printf("dem_step memory_triad_1thread %.1f GB/s\n", TriadBandwidth(1));
  std::printf("dem_step memory_triad_2threads %.1f GB/s\n", TriadBandwidth(2));
  // the ceiling: the law alone on blocks in L1, per instance (pairs per second, one thread)
  for (PairKernel k : {PairKernel::kVectorAvx512, PairKernel::kVectorAvx2, PairKernel::kVectorBaseline}) try {
      const double r = PairLawThroughput(k, SoilContactLaw(soil), soil.diameter, 1.5e-5, 2000000);
      std::printf("dem_step law_only_%s %.1f Mpairs/s\n", PairKernelName(k), r * 1e-6);
    } catch (const ConfigError&) {
      std::printf("# dem_step law_only_%d: not on this CPU\n", static_cast<int>(k));
    }
  {
    // the compute ceiling of the second core: the default kernel's law alone on both threads at
    // once (each on a block of its own, in L1; the threads' rates added), over one thread alone
    double one = 0.0, both = 0.0;
    for (int rep = 0; rep < 3; ++rep) {
      one = std::max(one, PairLawThroughput(PairKernel::kAuto, SoilContactLaw(soil), soil.diameter, 1.5e-5, 4000000));
      double sum = 0.0;
#pragma omp parallel num_threads(2) reduction(+ : sum)
      sum += PairLawThroughput(PairKernel::kAuto, SoilContactLaw(soil), soil.diameter, 1.5e-5, 4000000);
      both = std::max(both, sum);
    }
    std::printf("dem_step law_only_speedup_1_to_2 %.3f x\n", both / one);
  }
  const DemSystem bed_a = ReferenceBed(soil);
  std::printf("dem_step bed_particles %d count\n", bed_a.num_alive());
  std::printf("dem_step bed_contacts %d count\n", bed_a.contacts());
  Report("bed", bed_a, steps);
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
  std::printf("dem_step poured_preparation %.1f s\n", prep.wall_time);
  std::printf("dem_step poured_preparation_simulated %.3f s\n", prep.sim_time);
  std::printf("dem_step poured_density %.0f kg/m^3\n", prep.density_consolidated);
  Report("poured", *bed, steps);
  return 0;
}
