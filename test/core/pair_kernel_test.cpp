// The pair kernels: each vector instance (AVX-512, AVX2, baseline) gives the scalar reference's
// forces, maxima, overlaps and contact histories bit for bit, on random pairs that reach every
// branch of the law, and a DEM run on it gives the scalar run's states bit for bit; the plastic
// ledger's vector pass gives the scalar pass's energies bit for bit. Every comparison is a test
// per instance, not only the one kAuto picks; an instance this CPU cannot run is a GTest skip
// naming the instruction set it lacks (test/allowed_skips.yaml lists those skips, and no other).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/dem/pair_sweep.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool SameBits(const Vector3d& a, const Vector3d& b) {
  return SameBits(a.x(), b.x()) && SameBits(a.y(), b.y()) && SameBits(a.z(), b.z());
}

// The vector instances, each a parameter of the comparisons below. One this CPU cannot run skips
// the test with ResolvePairKernel's reason ("this CPU lacks ...").
class VectorInstance : public ::testing::TestWithParam<PairKernel> {
 protected:
  void SetUp() override {
    try {
      ResolvePairKernel(GetParam());
    } catch (const ConfigError& e) {
      GTEST_SKIP() << e.what();
    }
  }
};

// What one sweep produces.
struct SweepOut {
  std::vector<Vector3d> f, spring;
  std::vector<double> max_repulsion, normal_sum, adhesion_reach, contacts, overlap;
  std::vector<unsigned char> touching;
};

SweepOut Sweep(const SoilContactLaw& law, double D, double dt, int threads, ParticleStore ps, NeighbourList lists,
               PairKernel kernel) {
  for (int i = 0; i < ps.slots(); ++i) {
    ps.f[i].setZero();
    ps.max_repulsion[i] = ps.normal_sum[i] = ps.adhesion_reach[i] = ps.contacts[i] = ps.overlap[i] = 0.0;
  }
  SweepPairs(law, D, dt, threads, &ps, &lists, kernel);
  SweepOut o{ps.f, {}, ps.max_repulsion, ps.normal_sum, ps.adhesion_reach, ps.contacts, ps.overlap, lists.touching()};
  for (const TangentialHistory& h : lists.histories()) o.spring.push_back(h.spring);
  return o;
}

void ExpectSameBits(const SweepOut& a, const SweepOut& b, const char* what) {
  ASSERT_EQ(a.f.size(), b.f.size());
  int bad = 0;
  for (size_t i = 0; i < a.f.size(); ++i)
    bad += !SameBits(a.f[i], b.f[i]) || !SameBits(a.max_repulsion[i], b.max_repulsion[i]) ||
           !SameBits(a.normal_sum[i], b.normal_sum[i]) || !SameBits(a.adhesion_reach[i], b.adhesion_reach[i]) ||
           !SameBits(a.contacts[i], b.contacts[i]) ||
           !SameBits(a.overlap[i], b.overlap[i]);
  for (size_t k = 0; k < a.spring.size(); ++k) bad += !SameBits(a.spring[k], b.spring[k]) || a.touching[k] != b.touching[k];
  EXPECT_EQ(bad, 0) << what << ": slots or contacts that differ from the scalar kernel";
}

// 4000 random pairs of particles (each pair far from the others, so each branch of the law is met
// in isolation; separations from a gap of 0.05 d to an overlap of 0.25 d: adhesion, repulsion, the
// skin), then a dense random cluster of 500 (overlaps up to 0.3 d); random velocities.
ParticleStore PairsAndACluster(double D, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  auto random_unit = [&] {
    Vector3d n;
    do n = Vector3d(u(rng), u(rng), u(rng));
    while (n.norm() < 0.1 || n.norm() > 1.0);
    return n.normalized();
  };
  ParticleStore ps;
  bool appended = false;
  const int pairs = 4000;
  for (int p = 0; p < pairs; ++p) {
    const Vector3d c(3.0 * D * (p % 20), 3.0 * D * ((p / 20) % 20), 3.0 * D * (p / 400));
    const Vector3d n = random_unit();
    const double overlap = D * (-0.05 + 0.3 * u01(rng));
    const double dist = D - overlap;
    const Vector3d v = 0.3 * Vector3d(u(rng), u(rng), u(rng));
    ps.Add(c + 0.5 * dist * n, v, Vector3d::Zero(), 0.0, SlotState::kListed, &appended);
    ps.Add(c - 0.5 * dist * n, -v, Vector3d::Zero(), 0.0, SlotState::kListed, &appended);
  }
  const Vector3d corner(0.0, 0.0, 30.0 * D);
  for (int i = 0; i < 500; ++i)
    ps.Add(corner + 4.0 * D * Vector3d(u01(rng), u01(rng), u01(rng)), 0.5 * Vector3d(u(rng), u(rng), u(rng)),
           Vector3d::Zero(), 0.0, SlotState::kListed, &appended);
  return ps;
}

// Random pairs of particles and a cluster (PairsAndACluster) with a wide list cutoff (half lists
// of 30-50 partners: several blocks per particle); random overlaps, velocities, plastic deformations, adhesions and
// anchor springs. The branches are counted with the scalar law itself.
TEST_P(VectorInstance, GivesTheScalarKernelsResultsBitForBitOnEveryBranch) {
  const PairKernel kernel = GetParam();
  SoilParams soil = Nominal();
  const SoilContactLaw law(soil);
  const double D = soil.diameter, d0 = law.d0, dt = 2e-5;
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  ParticleStore ps = PairsAndACluster(D, rng);
  NeighbourList lists(2.0 * D, 2);
  lists.Build(&ps, 1);
  for (int i = 0; i < ps.slots(); ++i) {
    ps.plastic[i] = u01(rng) < 0.3 ? 0.0 : 0.06 * D * u01(rng);
    ps.adhesion_max[i] = u01(rng) < 0.1 ? 0.0 : MaxAdhesionForce(soil, ps.plastic[i]) * (0.5 + u01(rng));
  }
  // anchor springs: small (stick) to far beyond the cap (slip); some contacts new (not touching before)
  const double cap_scale = soil.friction * law.k_n * 0.05 * D / law.friction.k_t;
  int longest = 0;
  for (int i = 0; i < ps.slots(); ++i) {
    longest = std::max(longest, lists.end(i) - lists.begin(i));
    for (int k = lists.begin(i); k < lists.end(i); ++k) {
      // the solver's invariant: a pair that did not touch has no spring
      const double r = u01(rng);
      lists.touching()[k] = r > 0.2;
      lists.histories()[k].spring =
          r > 0.2 ? Vector3d(Vector3d(u(rng), u(rng), u(rng)) * cap_scale * 3.0 * r) : Vector3d::Zero();
    }
  }
  // (a block holds 32 lanes: short lists share one, a long one takes several on its own)
  EXPECT_GT(longest, 2 * 32) << "some particle's half list spans several blocks";

  // the branches, by the scalar law on each listed pair
  int skin = 0, adhesion = 0, repulsion = 0, loading = 0, unloading = 0, stick = 0, slip = 0, no_cohesion = 0;
  for (int i = 0; i < ps.slots(); ++i)
    for (int k = lists.begin(i); k < lists.end(i); ++k) {
      const int j = lists.partners()[k];
      const Vector3d r = ps.x[i] - ps.x[j];
      const double dist = r.norm(), d = D - dist - (ps.plastic[i] + ps.plastic[j]);
      if (dist >= D) continue;
      if (!(d > 0.0)) {
        ++skin;
        continue;
      }
      const Vector3d n = r / dist, vr = ps.v[i] - ps.v[j];
      const double vn = vr.dot(n);
      const double fmax = std::min(ps.adhesion_max[i], ps.adhesion_max[j]);
      const SoilNormalForce fn = law.Normal(d, -vn, fmax);
      (d < d0 ? adhesion : repulsion) += 1;
      no_cohesion += fmax == 0.0;
      (-vn > 0.0 ? loading : unloading) += 1;
      TangentialHistory h = lists.histories()[k];
      bool slipped = false;
      Vector3d s = h.spring - h.spring.dot(n) * n;
      s += (vr - vn * n) * dt;
      law.friction.Force(vr - vn * n, fn.repulsion, &s, &slipped);
      (slipped ? slip : stick) += 1;
    }
  std::printf("branches: in the skin %d, adhesion %d, repulsion %d, loading %d, unloading %d, stick %d, slip %d, "
              "no adhesion %d\n", skin, adhesion, repulsion, loading, unloading, stick, slip, no_cohesion);
  for (int c : {skin, adhesion, repulsion, loading, unloading, stick, slip, no_cohesion}) EXPECT_GT(c, 50);

  const SweepOut ref = Sweep(law, D, dt, 1, ps, lists, PairKernel::kScalar);
  // the outputs that drive the plastic relaxation (PlasticDrive): particles pulled apart on the
  // whole, and particles with adhesive contacts whose adhesion is their partner's (no reach)
  int pulled = 0, reach_elsewhere = 0;
  for (int i = 0; i < ps.slots(); ++i) {
    pulled += ref.normal_sum[i] < 0.0;
    reach_elsewhere += ref.normal_sum[i] < 0.0 && ref.adhesion_reach[i] == 0.0;
  }
  EXPECT_GT(pulled, 50) << "particles pulled apart";
  EXPECT_GT(reach_elsewhere, 20) << "pulled particles whose adhesion is their partners'";
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    ExpectSameBits(ref, Sweep(law, D, dt, threads, ps, lists, kernel), PairKernelName(kernel));
  }
  // without cohesion (the law's other instance)
  soil.cohesion = false;
  const SoilContactLaw plain(soil);
  const SweepOut ref_plain = Sweep(plain, D, dt, 1, ps, lists, PairKernel::kScalar);
  ExpectSameBits(ref_plain, Sweep(plain, D, dt, 2, ps, lists, kernel), "no cohesion");
}

// The plastic ledger's pass (PlasticExchangeEnergies) on the pairs and the cluster: each slot's
// deformation and adhesion changed (loading and relaxing) or not, a free slot among them. Every
// vector instance gives the scalar reference's per-slot sums bit for bit, for 1 and 2 threads,
// with and without cohesion. The branches are counted with NormalEnergy itself.
TEST_P(VectorInstance, ThePlasticLedgersVectorPassGivesTheScalarSumsBitForBit) {
  const PairKernel kernel = GetParam();
  SoilParams soil = Nominal();
  const SoilContactLaw law(soil);
  const double D = soil.diameter;
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  ParticleStore ps = PairsAndACluster(D, rng);
  NeighbourList lists(2.0 * D, 2);
  lists.Build(&ps, 1);
  std::vector<PlasticChange> rec(ps.slots());
  for (int i = 0; i < ps.slots(); ++i) {
    PlasticChange& r = rec[i];
    r.x = ps.x[i];
    r.p0 = u01(rng) < 0.2 ? 0.0 : 0.06 * D * u01(rng);
    r.a0 = u01(rng) < 0.1 ? 0.0 : MaxAdhesionForce(soil, r.p0);
    const double c = u01(rng);  // unchanged, loaded (more deformation) or relaxed (less)
    r.p1 = c < 0.3 ? r.p0 : std::max(0.0, r.p0 + 0.02 * D * (c < 0.65 ? u01(rng) : -u01(rng)));
    r.a1 = r.p1 == r.p0 ? r.a0 : MaxAdhesionForce(soil, r.p1);
  }
  ps.state[17] = SlotState::kFree;
  int unchanged = 0, out_of_reach = 0, adhesion = 0, repulsion = 0, rising = 0, falling = 0, longest = 0;
  for (int i = 0; i < ps.slots(); ++i) {
    longest = std::max(longest, lists.end(i) - lists.begin(i));
    for (int k = lists.begin(i); k < lists.end(i); ++k) {
      const PlasticChange &ri = rec[i], &rj = rec[lists.partners()[k]];
      unchanged += ri.p1 == ri.p0 && rj.p1 == rj.p0;
      const double gap = D - (ri.x - rj.x).norm();
      for (double p : {ri.p0 + rj.p0, ri.p1 + rj.p1}) {
        const double d = gap - p;
        if (!(d > 0.0)) {
          ++out_of_reach;
          continue;
        }
        (d < law.d0 ? adhesion : repulsion) += 1;
        if (d < law.d0) (d <= law.dp ? rising : falling) += 1;
      }
    }
  }
  std::printf("ledger branches: unchanged pairs %d, out of reach %d, adhesion %d (rising %d, falling %d), "
              "repulsion %d; longest half list %d\n", unchanged, out_of_reach, adhesion, rising, falling, repulsion, longest);
  for (int c : {unchanged, out_of_reach, rising, falling, repulsion}) EXPECT_GT(c, 50);
  EXPECT_GT(longest, 2 * 32) << "some particle's half list spans several blocks";
  auto run = [&](const SoilContactLaw& l, int threads, PairKernel k) {
    std::vector<double> de(ps.slots(), -1.0);
    PlasticExchangeEnergies(l, D, threads, ps, lists, rec.data(), de.data(), k);
    return de;
  };
  for (bool cohesion : {true, false}) {
    soil.cohesion = cohesion;
    const SoilContactLaw l(soil);
    const std::vector<double> ref = run(l, 1, PairKernel::kScalar);
    EXPECT_EQ(ref[17], 0.0);
    int moved = 0;
    for (double e : ref) moved += e != 0.0;
    EXPECT_GT(moved, ps.slots() / 4) << "slots whose pairs moved energy";
    for (int threads : {1, 2}) {
      const std::vector<double> de = run(l, threads, kernel);
      int bad = 0;
      for (int i = 0; i < ps.slots(); ++i) bad += !SameBits(ref[i], de[i]);
      EXPECT_EQ(bad, 0) << PairKernelName(kernel) << ", " << threads << " threads, cohesion " << cohesion
                        << ": slots whose sum differs from the scalar pass";
    }
  }
}

// A poured cohesive bed stepped on `kernel` for 300 steps (contacts made and broken, plasticity,
// walls), with the plastic ledger on.
DemSystem PouredBedRun(PairKernel kernel) {
  const SoilParams soil = Nominal();
  const double D = soil.diameter;
  DemSettings st;
  st.threads = 2;
  st.pair_kernel = kernel;
  DemSystem s(soil, st);
  for (DemWall& w : MakeOpenBoxWalls(12 * D, 12 * D, 30 * D)) s.AddWall(std::move(w));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 11; ++j)
      for (int i = 0; i < 11; ++i)
        s.AddParticle(Vector3d((i + 0.7 + 0.1 * u(rng)) * D, (j + 0.7 + 0.1 * u(rng)) * D, (k + 0.6) * 0.93 * D),
                      Vector3d(0.1 * (u(rng) - 0.5), 0.1 * (u(rng) - 0.5), -0.3));
  s.Finalize(0.5 * s.CriticalTimeStep().dt_crit);
  s.set_plastic_ledger(true);
  for (int i = 0; i < 300; ++i) s.Step();
  return s;
}

// The bed on each vector instance: the scalar run's states and plastic ledger to the bit (the
// scalar run made once for all instances: the sanitizer build runs this test too).
TEST_P(VectorInstance, ADemRunOnItIsTheScalarRunBitForBit) {
  const PairKernel vector = GetParam();
  static const DemSystem ref = PouredBedRun(PairKernel::kScalar);
  EXPECT_GT(ref.contacts(), 1000);
  EXPECT_NE(ref.plastic_exchange(), 0.0);
  const DemSystem s = PouredBedRun(vector);
  EXPECT_EQ(s.pair_kernel(), vector);
  int bad = 0;
  for (int id = 0; id < ref.size(); ++id)
    bad += !SameBits(ref.position(id), s.position(id)) || !SameBits(ref.velocity(id), s.velocity(id)) ||
           !SameBits(ref.plastic_deformation(id), s.plastic_deformation(id));
  EXPECT_EQ(bad, 0) << PairKernelName(vector) << ": particles whose state differs from the scalar run";
  EXPECT_TRUE(SameBits(ref.plastic_exchange(), s.plastic_exchange())) << PairKernelName(vector) << ": the plastic ledger";
}

// Slots without a pair before slots with pairs (a block holds the pairs of consecutive slots and
// takes each slot in its turn, a slot without pairs too): a sparse lattice of 300 particles, those
// of its last row along x each with a partner in contact beside it. Each slot's force starts at -0:
// the scalar kernel adds its zero pair sum (+0) to it, so a slot the vector kernel skipped would
// keep -0.
TEST_P(VectorInstance, TakesSlotsWithoutPairsInTheirTurnInABlock) {
  const PairKernel kernel = GetParam();
  const SoilParams soil = Nominal();
  const SoilContactLaw law(soil);
  const double D = soil.diameter, dt = 2e-5;
  ParticleStore ps;
  bool appended = false;
  for (int p = 0; p < 300; ++p) {
    const Vector3d c(3.0 * D * (p % 10), 3.0 * D * ((p / 10) % 10), 3.0 * D * (p / 100));
    ps.Add(c, Vector3d(0.01 * p, 0.0, 0.0), Vector3d::Zero(), 0.0, SlotState::kListed, &appended);
    if (p % 10 == 9)  // the last row along x: its slots come after a run of slots without pairs
      ps.Add(c + Vector3d(0.97 * D, 0.0, 0.0), Vector3d::Zero(), Vector3d::Zero(), 0.0, SlotState::kListed, &appended);
  }
  NeighbourList lists(1.5 * D, 2);
  lists.Build(&ps, 1);
  int empty_run = 0, longest_empty_run = 0, pairs = 0;
  for (int i = 0; i < ps.slots(); ++i) {
    const int m = lists.end(i) - lists.begin(i);
    pairs += m;
    empty_run = m == 0 ? empty_run + 1 : 0;
    longest_empty_run = std::max(longest_empty_run, empty_run);
  }
  EXPECT_EQ(pairs, 30);
  EXPECT_GT(longest_empty_run, 40) << "more slots without pairs in a row than a block holds slots (32)";
  auto sweep = [&](PairKernel k, int threads) {
    ParticleStore p = ps;
    NeighbourList l = lists;
    for (int i = 0; i < p.slots(); ++i) {
      p.f[i] = Vector3d(-0.0, -0.0, -0.0);
      p.max_repulsion[i] = p.normal_sum[i] = p.adhesion_reach[i] = p.contacts[i] = p.overlap[i] = 0.0;
    }
    SweepPairs(law, D, dt, threads, &p, &l, k);
    SweepOut o{p.f, {}, p.max_repulsion, p.normal_sum, p.adhesion_reach, p.contacts, p.overlap, l.touching()};
    for (const TangentialHistory& h : l.histories()) o.spring.push_back(h.spring);
    return o;
  };
  const SweepOut ref = sweep(PairKernel::kScalar, 1);
  int negative_zero = 0;
  for (const Vector3d& f : ref.f) negative_zero += f.x() == 0.0 && std::signbit(f.x());
  EXPECT_EQ(negative_zero, 0) << "the scalar kernel adds +0 to a slot without pairs";
  for (int threads : {1, 2}) ExpectSameBits(ref, sweep(kernel, threads), PairKernelName(kernel));
}

// Test names end in the instance: PairKernel/VectorInstance.<test>/avx512, /avx2, /baseline.
INSTANTIATE_TEST_SUITE_P(PairKernel, VectorInstance,
                         ::testing::Values(PairKernel::kVectorAvx512, PairKernel::kVectorAvx2, PairKernel::kVectorBaseline),
                         [](const ::testing::TestParamInfo<PairKernel>& i) -> std::string {
                           switch (i.param) {
                             case PairKernel::kVectorAvx512: return "avx512";
                             case PairKernel::kVectorAvx2: return "avx2";
                             default: return "baseline";
                           }
                         });

TEST(PairKernel, AutoTakesTheBestInstanceTheCpuHas) {
  const PairKernel k = ResolvePairKernel(PairKernel::kAuto);
  EXPECT_NE(k, PairKernel::kAuto);
  EXPECT_NE(k, PairKernel::kScalar);
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw")) {
    EXPECT_EQ(k, PairKernel::kVectorAvx512);
  } else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    EXPECT_EQ(k, PairKernel::kVectorAvx2);
  }
  std::printf("this CPU: %s\n", PairKernelName(PairKernel::kAuto));
}

}  // namespace
}  // namespace dem_mobility::core
