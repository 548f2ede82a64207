// The pair sweep and its two kernels (see pair_sweep.h); the plastic ledger's pass over the same
// lists is in plastic_ledger_pass.cpp. Both files are compiled with
// -ffp-contract=off (no fused multiply-adds: every instance rounds as the scalar law does),
// -fno-math-errno and -fno-trapping-math (sqrt and division may run on lanes whose result is then
// discarded); none of these changes a result.
#include "dem_mobility/core/dem/pair_sweep.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/dem/dem_energy.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

using pair_kernels::InstanceOf;
using pair_kernels::kBlock;
using pair_kernels::kPad;

// ---------------------------------------------------------------------------------------------
// the slabs' schedule

// Runs sweep(slab) on every slab, on `threads` threads, with each particle's sums added in the
// order of the two colours one after the other (every even slab, then every odd one), but without
// the barrier between them. A slab writes to its own particles and the next slab's, so an odd slab
// shares particles with the even slabs beside it only: it must run after both, and may run beside
// any other slab. The threads take the slabs in a fixed order, the even ones ascending, each odd
// slab o right after the even slab o + 1 + 2 threads (or at the end): by the time a thread takes
// an odd slab, the even slabs it waits for were taken 2 threads slabs earlier and are (nearly
// always) done. A thread waits only for those two, not for the other thread's last slab of a
// colour. Slabs never depend on the thread count (neighbour_list.h): the same sums for any.
template <class Sweep>
void SweepSlabs(int ns, int threads, const Sweep& sweep) {
  constexpr int kMaxSlabs = 64;  // (NeighbourList::SetUpSlabs makes at most 64)
  DM_DEMAND(ns <= kMaxSlabs);
  std::array<int, kMaxSlabs> order;
  std::array<std::atomic<int>, kMaxSlabs> done;
  const int lag = 1 + 2 * threads;
  int m = 0, next_odd = 1;
  for (int e = 0; e < ns; e += 2) {
    order[m++] = e;
    if (e - lag >= next_odd) {
      order[m++] = next_odd;
      next_odd += 2;
    }
  }
  for (; next_odd < ns; next_odd += 2) order[m++] = next_odd;
  for (int s = 0; s < ns; ++s) done[s].store(0, std::memory_order_relaxed);
  std::atomic<int> next{0};
  auto ready = [&](int s) { return s < 0 || s >= ns || done[s].load(std::memory_order_acquire) != 0; };
#pragma omp parallel num_threads(threads)
  for (int k = next.fetch_add(1, std::memory_order_relaxed); k < ns; k = next.fetch_add(1, std::memory_order_relaxed)) {
    const int sl = order[k];
    if (sl % 2 == 1)
      for (int spins = 0; !(ready(sl - 1) && ready(sl + 1)); ++spins) {
        if (spins < 1 << 14) {
#if defined(__x86_64__) || defined(__i386__)
          __builtin_ia32_pause();
#endif
        } else {
          std::this_thread::yield();  // (the other thread may not be running: more threads than cores)
        }
      }
    sweep(sl);
    done[sl].store(1, std::memory_order_release);
  }
}

// ---------------------------------------------------------------------------------------------
// the scalar reference: the soil law's per-pair functions, one contact after the other

void SweepScalar(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                 NeighbourList* lists) {
  const double D = diameter, D2 = D * D;
  std::vector<Vector3d>& x = ps->x;
  std::vector<Vector3d>& v = ps->v;
  const std::vector<double>& plastic = ps->plastic;
  const std::vector<double>& adhesion_max = ps->adhesion_max;
  PairSums* sums = ps->sums.data();
  const std::vector<int>& nbr_begin = lists->list_begin();
  const std::vector<int>& nbr_end = lists->list_end();
  const std::vector<int>& nbr = lists->partners();
  std::vector<TangentialHistory>& hist = lists->histories();
  std::vector<unsigned char>& touching = lists->touching();
  auto sweep = [&](int i) {
    const Vector3d xi = x[i], vi = v[i];
    const double pi = plastic[i], ai = adhesion_max[i];
    Vector3d fi = Vector3d::Zero();
    PairSums& si = sums[i];
    double max_rep = si.max_repulsion, normal_sum = si.normal_sum, reach_sum = si.adhesion_reach;
    double contacts = si.contacts, max_overlap = si.overlap;
    for (int k = nbr_begin[i]; k < nbr_end[i]; ++k) {
      const int j = nbr[k];
      const Vector3d r = xi - x[j];
      const double r2 = r.squaredNorm();
      if (r2 >= D2) {  // in the skin, not touching
        if (touching[k]) {
          hist[k] = TangentialHistory();
          touching[k] = 0;
        }
        continue;
      }
      const double dist = std::sqrt(r2);
      const double overlap = D - dist;
      PairSums& sj = sums[j];
      max_overlap = std::max(max_overlap, overlap);
      sj.overlap = std::max(sj.overlap, overlap);
      // effective penetration: the overlap less both particles' plastic deformation
      const double d = overlap - (pi + plastic[j]);
      if (!(d > 0.0) || dist <= 0.0) {
        if (touching[k]) {
          hist[k] = TangentialHistory();
          touching[k] = 0;
        }
        continue;
      }
      const Vector3d nrm = r * (1.0 / dist);  // from j toward i
      const Vector3d vr = vi - v[j];
      const double vn = vr.dot(nrm);
      const double aj = adhesion_max[j];
      const SoilNormalForce fn = law.Normal(d, -vn, std::min(ai, aj));
      const Vector3d vt = vr - vn * nrm;
      const Vector3d fc = fn.Total() * nrm + law.Tangential(nrm, vt, fn.repulsion, dt, &hist[k]);
      fi += fc;
      sj.f[0] -= fc.x();
      sj.f[1] -= fc.y();
      sj.f[2] -= fc.z();
      // the plastic drive (PlasticDrive): the elastic normal force on both, the reach on the end(s)
      // whose adhesion is the pair's
      const double elastic = fn.adhesion + fn.repulsion;
      const double reach = law.cohesion ? AdhesionReach(law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d) : 0.0;
      max_rep = std::max(max_rep, fn.repulsion);
      normal_sum += elastic;
      reach_sum += ai <= aj ? reach : 0.0;
      contacts += 1.0;
      sj.max_repulsion = std::max(sj.max_repulsion, fn.repulsion);
      sj.normal_sum += elastic;
      sj.adhesion_reach += aj <= ai ? reach : 0.0;
      sj.contacts += 1.0;
      touching[k] = 1;
    }
    si.f[0] += fi.x();
    si.f[1] += fi.y();
    si.f[2] += fi.z();
    si.max_repulsion = max_rep;
    si.normal_sum = normal_sum;
    si.adhesion_reach = reach_sum;
    si.contacts = contacts;
    si.overlap = max_overlap;
  };
  const std::vector<SlotState>& state = ps->state;
  SweepSlabs(lists->num_slabs(), threads, [&](int sl) {
    for (int i = lists->slab_start(sl); i < lists->slab_start(sl + 1); ++i)
      if (state[i] == SlotState::kListed) sweep(i);
    for (const int i : lists->slab_added(sl)) sweep(i);
  });
}

// ---------------------------------------------------------------------------------------------
// the vector kernel

// The law's constants as the block loop reads them (the scalar law's, worked out the same way).
struct LawConstants {
  double D, D2, dt, k_n, c_n, d0, dp, inv_dp, inv_d0_dp, s_n;
  double mu, k_t, inv_k_t, v_slip, c_visc;
  bool cohesion;
  double step_per_mass;  // dt / the Coulomb dashpot's mass (SoilContactLaw::inv_damped_mass)
};

// The sweep's arrays (what the scalar kernel reads through ps and lists).
struct SweepArrays {
  const HotParticle* hot;
  PairSums* sums;
  const int *nbr_begin, *nbr_end, *nbr;
  TangentialHistory* hist;
  unsigned char* touching;
};

// One block's lanes: inputs gathered, outputs of the law.
struct alignas(64) Block {
  double rx[kBlock], ry[kBlock], rz[kBlock];     // x_i - x_j
  double vx[kBlock], vy[kBlock], vz[kBlock];     // v_i - v_j
  double psum[kBlock], amax[kBlock];             // plastic_i + plastic_j, min(adhesion_i, adhesion_j)
  double own_i[kBlock], own_j[kBlock];           // 1: the pair's adhesion is i's (j's), adhesion_i <= adhesion_j
  double sx[kBlock], sy[kBlock], sz[kBlock];     // the anchor spring: in, and out
  double fx[kBlock], fy[kBlock], fz[kBlock];     // the contact force on i
  double rep[kBlock], ovl[kBlock];               // repulsion, overlap
  double elastic[kBlock];                        // adhesion + repulsion
  double reach_i[kBlock], reach_j[kBlock];       // AdhesionReach on the end(s) whose adhesion is the pair's
  double contact[kBlock];                        // 1: in contact (d > 0)
};

// The law on lanes [0, n) of a block, n a multiple of kPad: the scalar law's operations in its
// order (sums associated as Eigen's: (a0 b0 + a1 b1) + a2 b2), its branches as selects (the soil's
// cohesion switch as a template argument: the vectoriser takes no select on a loop-invariant bool).
template <bool kCohesion>
[[gnu::always_inline]] inline void BlockLaw(const LawConstants& law, int n, Block* __restrict b) {
  const LawConstants c = law;  // in registers: no constant is loaded under a lane's condition
  for (int l = 0; l < n; ++l) {
    const double rx = b->rx[l], ry = b->ry[l], rz = b->rz[l];
    const double r2 = (rx * rx + ry * ry) + rz * rz;
    const double dist = std::sqrt(r2);
    const double overlap = c.D - dist;
    const double d = overlap - b->psum[l];
    const bool skin = r2 < c.D2;
    const bool contact = skin & (d > 0.0) & (dist > 0.0);
    const double inv = 1.0 / dist;
    const double nx = rx * inv, ny = ry * inv, nz = rz * inv;
    const double vx = b->vx[l], vy = b->vy[l], vz = b->vz[l];
    const double vn = (vx * nx + vy * ny) + vz * nz;
    // the normal force (SoilContactLaw::Normal) at d, d_dot = -vn
    const double d_dot = -vn;
    const double fa = std::max(0.0, b->amax[l]);
    const double tri = std::max(0.0, std::min(d * c.inv_dp, (c.d0 - d) * c.inv_d0_dp));
    const double adhesion = kCohesion ? -fa * tri : 0.0;
    const double repulsion = c.k_n * std::max(0.0, d - c.d0);
    const double damping = c.c_n * (std::max(d_dot, 0.0) + c.s_n * std::min(d_dot, 0.0));
    const double elastic = adhesion + repulsion;
    const double total = elastic + damping;
    const double reach = kCohesion ? AdhesionReach(c.d0, c.dp, c.inv_dp, c.inv_d0_dp, d) : 0.0;
    // the tangential force (SoilContactLaw::Tangential, AsperityFriction::Force)
    const double vtx = vx - vn * nx, vty = vy - vn * ny, vtz = vz - vn * nz;
    double sx = b->sx[l], sy = b->sy[l], sz = b->sz[l];
    const double sn = (sx * nx + sy * ny) + sz * nz;
    sx -= sn * nx;
    sy -= sn * ny;
    sz -= sn * nz;
    sx += vtx * c.dt;
    sy += vty * c.dt;
    sz += vtz * c.dt;
    const double vt_norm = std::sqrt((vtx * vtx + vty * vty) + vtz * vtz);
    const double cc = AsperityFriction::CoulombDamping(c.mu, repulsion, c.v_slip, vt_norm, c.step_per_mass);
    const double fcx = cc * vtx, fcy = cc * vty, fcz = cc * vtz;
    double ftx = -c.k_t * sx + fcx, fty = -c.k_t * sy + fcy, ftz = -c.k_t * sz + fcz;
    const double limit = c.mu * std::max(0.0, repulsion);
    const double ft2 = (ftx * ftx + fty * fty) + ftz * ftz;
    const bool slip = ft2 > limit * limit;
    const double scale = ft2 > 0.0 ? limit / std::sqrt(ft2) : 0.0;
    const double stx = ftx * scale, sty = fty * scale, stz = ftz * scale;
    ftx = slip ? stx : ftx;
    fty = slip ? sty : fty;
    ftz = slip ? stz : ftz;
    sx = slip ? -(ftx - fcx) * c.inv_k_t : sx;
    sy = slip ? -(fty - fcy) * c.inv_k_t : sy;
    sz = slip ? -(ftz - fcz) * c.inv_k_t : sz;
    ftx -= c.c_visc * vtx;
    fty -= c.c_visc * vty;
    ftz -= c.c_visc * vtz;
    // a lane without contact scatters nothing: zero force, spring and maxima (adding +0 changes no
    // sum: a particle's sum starts at +0 and so is never -0), its overlap only where it is within
    // the diameter; its spring is reset (it is zero already when the pair did not touch before)
    b->sx[l] = contact ? sx : 0.0;
    b->sy[l] = contact ? sy : 0.0;
    b->sz[l] = contact ? sz : 0.0;
    b->fx[l] = contact ? total * nx + ftx : 0.0;
    b->fy[l] = contact ? total * ny + fty : 0.0;
    b->fz[l] = contact ? total * nz + ftz : 0.0;
    b->rep[l] = contact ? repulsion : 0.0;
    b->elastic[l] = contact ? elastic : 0.0;
    b->reach_i[l] = contact ? reach * b->own_i[l] : 0.0;
    b->reach_j[l] = contact ? reach * b->own_j[l] : 0.0;
    b->ovl[l] = skin ? overlap : 0.0;
    b->contact[l] = contact ? 1.0 : 0.0;
  }
}

// Lanes [lane0, lane0 + m) of a block: slot i's pairs k0 .. k0 + m - 1 gathered (the partners' hot
// records are only read during a sweep, so any number of slots may be gathered before any is
// scattered).
[[gnu::always_inline]] inline void GatherLanes(const SweepArrays& a, int i, int k0, int m, int lane0, Block* b) {
  const HotParticle& pi = a.hot[i];
  const double xi0 = pi.x[0], xi1 = pi.x[1], xi2 = pi.x[2];
  const double vi0 = pi.v[0], vi1 = pi.v[1], vi2 = pi.v[2];
  const double plastic_i = pi.plastic, adhesion_i = pi.adhesion_max;
  for (int l = 0; l < m; ++l) {
    const HotParticle& pj = a.hot[a.nbr[k0 + l]];
    const int q = lane0 + l;
    b->rx[q] = xi0 - pj.x[0];
    b->ry[q] = xi1 - pj.x[1];
    b->rz[q] = xi2 - pj.x[2];
    b->vx[q] = vi0 - pj.v[0];
    b->vy[q] = vi1 - pj.v[1];
    b->vz[q] = vi2 - pj.v[2];
    b->psum[q] = plastic_i + pj.plastic;
    b->amax[q] = std::min(adhesion_i, pj.adhesion_max);
    b->own_i[q] = adhesion_i <= pj.adhesion_max ? 1.0 : 0.0;
    b->own_j[q] = pj.adhesion_max <= adhesion_i ? 1.0 : 0.0;
    const Vector3d& sp = a.hist[k0 + l].spring;
    b->sx[q] = sp.x();
    b->sy[q] = sp.y();
    b->sz[q] = sp.z();
  }
}

// Lanes [m, n) of a block: padding, apart by two diameters, at rest, no contact.
[[gnu::always_inline]] inline void PadLanes(const LawConstants& c, int m, int n, Block* b) {
  for (int l = m; l < n; ++l) {
    b->rx[l] = b->ry[l] = b->rz[l] = 2.0 * c.D;
    b->vx[l] = b->vy[l] = b->vz[l] = b->psum[l] = b->amax[l] = b->own_i[l] = b->own_j[l] = 0.0;
    b->sx[l] = b->sy[l] = b->sz[l] = 0.0;
  }
}

// What one slot's sweep carries from block to block: its force sum, its plastic drive and its
// largest overlap.
struct SlotSums {
  double f0 = 0.0, f1 = 0.0, f2 = 0.0;
  double max_rep, normal_sum, reach_sum, contacts, max_overlap;
  explicit SlotSums(const PairSums& s)
      : max_rep(s.max_repulsion),
        normal_sum(s.normal_sum),
        reach_sum(s.adhesion_reach),
        contacts(s.contacts),
        max_overlap(s.overlap) {}
  void Into(PairSums* s) const {
    s->f[0] += f0;
    s->f[1] += f1;
    s->f[2] += f2;
    s->max_repulsion = max_rep;
    s->normal_sum = normal_sum;
    s->adhesion_reach = reach_sum;
    s->contacts = contacts;
    s->overlap = max_overlap;
  }
};

// The results of lanes [lane0, lane0 + m) (slot i's pairs k0 ...) scattered in list order, the
// scalar kernel's order of sums and maxima. No branch: a lane without contact adds zeros.
[[gnu::always_inline]] inline void ScatterLanes(const SweepArrays& a, int k0, int m, int lane0, const Block* b,
                                                SlotSums* si) {
  for (int l = 0; l < m; ++l) {
    const int q = lane0 + l, k = k0 + l, j = a.nbr[k];
    PairSums& sj = a.sums[j];
    si->max_overlap = std::max(si->max_overlap, b->ovl[q]);
    sj.overlap = std::max(sj.overlap, b->ovl[q]);
    si->f0 += b->fx[q];
    si->f1 += b->fy[q];
    si->f2 += b->fz[q];
    sj.f[0] -= b->fx[q];
    sj.f[1] -= b->fy[q];
    sj.f[2] -= b->fz[q];
    si->max_rep = std::max(si->max_rep, b->rep[q]);
    si->normal_sum += b->elastic[q];
    si->reach_sum += b->reach_i[q];
    sj.max_repulsion = std::max(sj.max_repulsion, b->rep[q]);
    sj.normal_sum += b->elastic[q];
    sj.adhesion_reach += b->reach_j[q];
    si->contacts += b->contact[q];
    sj.contacts += b->contact[q];
    a.hist[k].spring = Vector3d(b->sx[q], b->sy[q], b->sz[q]);
    a.touching[k] = static_cast<unsigned char>(b->contact[q] != 0.0);
  }
}

// A slot with more pairs than a block holds: its pairs block by block on their own.
template <bool kCohesion>
[[gnu::always_inline]] inline void SweepLongSlot(const LawConstants& c, const SweepArrays& a, int i, Block* b) {
  SlotSums si(a.sums[i]);
  for (int k0 = a.nbr_begin[i]; k0 < a.nbr_end[i]; k0 += kBlock) {
    const int m = std::min(kBlock, a.nbr_end[i] - k0);
    GatherLanes(a, i, k0, m, 0, b);
    const int n = (m + kPad - 1) / kPad * kPad;
    PadLanes(c, m, n, b);
    BlockLaw<kCohesion>(c, n, b);
    ScatterLanes(a, k0, m, 0, b, &si);
  }
  si.Into(&a.sums[i]);
}

// One slab: its listed slots in ascending order, then those added since the build. Consecutive
// slots share a block (a slot's half list holds 4-10 pairs in a packed bed: one slot per block
// would leave the law one vector, its sqrt and division chain waiting on each other): their pairs
// are gathered lane after lane, the law runs once over the block, and the slots are scattered one
// after the other in their order, each as it would be alone (a slot's sums are read when it is
// scattered, after those of the slots before it). The partners of the slot kAhead on, and its
// anchor springs, are fetched into the cache while this one is gathered: the slots of the next
// cell rows along the grid's slower axes lie a plane of cells further on, and the gather and
// scatter would wait for each of them (5 slots ahead and the springs too: 3-5 % off the sweep
// against 3 slots without the springs, interleaved runs of bed (a); 8 slots ahead was slower). (The two lambdas are always inlined: a lambda does not take its caller's target, and
// compiled on its own it would run the law on the baseline's SSE2 in every instance.)
template <bool kCohesion>
[[gnu::always_inline]] inline void SweepSlabOf(const LawConstants& c, const SweepArrays& a, const SlotState* state,
                                               int begin, int end, const std::vector<int>& added) {
  constexpr int kAhead = 5;
  Block b;
  int slots[kBlock];  // the block's slots, in order (one without pairs takes its turn too)
  int lanes = 0, count = 0;
  auto flush = [&]() __attribute__((always_inline)) {
    if (count == 0) return;
    const int n = (lanes + kPad - 1) / kPad * kPad;
    PadLanes(c, lanes, n, &b);
    BlockLaw<kCohesion>(c, n, &b);
    int lane0 = 0;
    for (int s = 0; s < count; ++s) {
      const int i = slots[s], k0 = a.nbr_begin[i], m = a.nbr_end[i] - k0;
      SlotSums si(a.sums[i]);
      ScatterLanes(a, k0, m, lane0, &b, &si);
      si.Into(&a.sums[i]);
      lane0 += m;
    }
    lanes = count = 0;
  };
  auto sweep = [&](int i) __attribute__((always_inline)) {
    const int m = a.nbr_end[i] - a.nbr_begin[i];
    if (m > kBlock) {  // rare: after the slots before it, on its own
      flush();
      SweepLongSlot<kCohesion>(c, a, i, &b);
      return;
    }
    if (lanes + m > kBlock || count == kBlock) flush();
    GatherLanes(a, i, a.nbr_begin[i], m, lanes, &b);
    slots[count++] = i;
    lanes += m;
  };
  for (int i = begin; i < end; ++i) {
    if (i + kAhead < end) {
      const int k0 = a.nbr_begin[i + kAhead], k1 = a.nbr_end[i + kAhead];
      for (int k = k0; k < k1; ++k) {
        const int j = a.nbr[k];
        __builtin_prefetch(&a.hot[j], 0, 3);
        __builtin_prefetch(&a.sums[j], 1, 3);
      }
      for (int k = k0; k < k1; k += 2) __builtin_prefetch(&a.hist[k], 1, 3);  // 24-byte springs
    }
    if (state[i] == SlotState::kListed) sweep(i);
  }
  for (const int i : added) sweep(i);
  flush();
}

[[gnu::always_inline]] inline void SweepSlabBody(const LawConstants& c, const SweepArrays& a, const SlotState* state,
                                                 int begin, int end, const std::vector<int>& added) {
  if (c.cohesion)
    SweepSlabOf<true>(c, a, state, begin, end, added);
  else
    SweepSlabOf<false>(c, a, state, begin, end, added);
}

// The law alone on one block, `reps` times (PairLawThroughput): each evaluation feeds its springs to
// the next, so that none is optimised away.
[[gnu::always_inline]] inline void LawOnlyBody(const LawConstants& c, Block* b, long reps) {
  for (long r = 0; r < reps; ++r) BlockLaw<true>(c, kBlock, b);
}
__attribute__((target("arch=x86-64-v4"))) void LawOnlyAvx512(const LawConstants& c, Block* b, long reps) {
  LawOnlyBody(c, b, reps);
}
__attribute__((target("arch=x86-64-v3"))) void LawOnlyAvx2(const LawConstants& c, Block* b, long reps) {
  LawOnlyBody(c, b, reps);
}
void LawOnlyBaseline(const LawConstants& c, Block* b, long reps) { LawOnlyBody(c, b, reps); }

using SlabFunction = void (*)(const LawConstants&, const SweepArrays&, const SlotState*, int, int,
                              const std::vector<int>&);

// The instances: one body, compiled for each instruction set (the body is inlined into each).
__attribute__((target("arch=x86-64-v4"))) void SweepSlabAvx512(const LawConstants& c, const SweepArrays& a,
                                                                const SlotState* state, int begin, int end,
                                                                const std::vector<int>& added) {
  SweepSlabBody(c, a, state, begin, end, added);
}
__attribute__((target("arch=x86-64-v3"))) void SweepSlabAvx2(const LawConstants& c, const SweepArrays& a,
                                                              const SlotState* state, int begin, int end,
                                                              const std::vector<int>& added) {
  SweepSlabBody(c, a, state, begin, end, added);
}
void SweepSlabBaseline(const LawConstants& c, const SweepArrays& a, const SlotState* state, int begin, int end,
                       const std::vector<int>& added) {
  SweepSlabBody(c, a, state, begin, end, added);
}

bool CpuHasAvx512() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx2") &&
         __builtin_cpu_supports("fma");
}
bool CpuHasAvx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
}

LawConstants ConstantsOf(const SoilContactLaw& law, double diameter, double dt) {
  const AsperityFriction& fr = law.friction;
  return LawConstants{diameter, diameter * diameter, dt,     law.k_n,    law.c_n,   law.d0,    law.dp,      law.inv_dp,
                      law.inv_d0_dp, law.s_n, fr.mu, fr.k_t, fr.inv_k_t, fr.v_slip, fr.c_visc, law.cohesion, dt * law.inv_damped_mass};
}

void SweepVector(SlabFunction slab, const SoilContactLaw& law, double diameter, double dt, int threads,
                 ParticleStore* ps, NeighbourList* lists) {
  const LawConstants c = ConstantsOf(law, diameter, dt);
  const SweepArrays a{ps->hot.data(),
                      ps->sums.data(),
                      lists->list_begin().data(),
                      lists->list_end().data(),
                      lists->partners().data(),
                      lists->histories().data(),
                      lists->touching().data()};
  const SlotState* state = ps->state.data();
  SweepSlabs(lists->num_slabs(), threads, [&](int sl) {
    slab(c, a, state, lists->slab_start(sl), lists->slab_start(sl + 1), lists->slab_added(sl));
  });
}

}  // namespace

PairKernel ResolvePairKernel(PairKernel requested) {
  switch (requested) {
    case PairKernel::kAuto:
      return CpuHasAvx512() ? PairKernel::kVectorAvx512
                            : (CpuHasAvx2() ? PairKernel::kVectorAvx2 : PairKernel::kVectorBaseline);
    case PairKernel::kVectorAvx512:
      DM_THROW_UNLESS(CpuHasAvx512(), "pair kernel vector-avx512: this CPU lacks AVX-512 (F, VL, DQ, BW)");
      return requested;
    case PairKernel::kVectorAvx2:
      DM_THROW_UNLESS(CpuHasAvx2(), "pair kernel vector-avx2: this CPU lacks AVX2, FMA or BMI2");
      return requested;
    case PairKernel::kVectorBaseline:
    case PairKernel::kScalar:
      return requested;
  }
  return PairKernel::kScalar;
}

const char* PairKernelName(PairKernel kernel) {
  switch (ResolvePairKernel(kernel)) {
    case PairKernel::kVectorAvx512: return "vector-avx512";
    case PairKernel::kVectorAvx2: return "vector-avx2";
    case PairKernel::kVectorBaseline: return "vector-baseline";
    default: return "scalar";
  }
}

void SweepPacked(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                 NeighbourList* lists, PairKernel kernel) {
  DM_DEMAND(static_cast<int>(ps->hot.size()) == ps->slots() && static_cast<int>(ps->sums.size()) == ps->slots());
  if (const SlabFunction slab = InstanceOf<SlabFunction>(kernel, SweepSlabAvx512, SweepSlabAvx2, SweepSlabBaseline))
    return SweepVector(slab, law, diameter, dt, threads, ps, lists);
  SweepScalar(law, diameter, dt, threads, ps, lists);
}

void SweepPairs(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                NeighbourList* lists, PairKernel kernel) {
  const int n = ps->slots();
  ps->SizeScratch();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    ps->PackFresh(i, ps->f[i]);
    PairSums& s = ps->sums[i];
    s.max_repulsion = ps->max_repulsion[i];
    s.normal_sum = ps->normal_sum[i];
    s.adhesion_reach = ps->adhesion_reach[i];
    s.contacts = ps->contacts[i];
    s.overlap = ps->overlap[i];
  }
  SweepPacked(law, diameter, dt, threads, ps, lists, kernel);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i) ps->Unpack(i);
}

double PairLawThroughput(PairKernel kernel, const SoilContactLaw& law, double diameter, double dt, long repetitions) {
  const LawConstants c = ConstantsOf(law, diameter, dt);
  Block b;
  for (int l = 0; l < kBlock; ++l) {  // pairs in contact about the repulsion onset, sliding and not
    const double t = l / double(kBlock);
    b.rx[l] = diameter * (0.94 + 0.02 * t);
    b.ry[l] = 0.01 * diameter * t;
    b.rz[l] = -0.02 * diameter * t;
    b.vx[l] = 0.01 * (t - 0.5);
    b.vy[l] = 0.02 * t;
    b.vz[l] = -0.01;
    b.psum[l] = 0.0;
    b.amax[l] = 1.0;
    b.own_i[l] = 1.0;
    b.own_j[l] = t < 0.5 ? 1.0 : 0.0;
    b.sx[l] = b.sy[l] = b.sz[l] = 0.0;
  }
  using LawOnly = void (*)(const LawConstants&, Block*, long);
  // (resolved first: a vector instance this CPU lacks is refused)
  const LawOnly run = InstanceOf<LawOnly>(ResolvePairKernel(kernel), LawOnlyAvx512, LawOnlyAvx2, LawOnlyBaseline);
  if (!run) throw ConfigError("PairLawThroughput: the scalar kernel has no block law");
  const auto t0 = std::chrono::steady_clock::now();
  run(c, &b, repetitions);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  DM_THROW_UNLESS(std::isfinite(b.sx[kBlock - 1]), "PairLawThroughput: non-finite spring");
  return static_cast<double>(repetitions) * kBlock / wall;
}

}  // namespace dem_mobility::core
