// The plastic ledger's pass over the neighbour lists (PlasticExchangeEnergies, pair_sweep.h): the
// energy each particle's plastic change moves through its contacts, a scalar reference and a
// vector kernel compiled for AVX-512, AVX2 and the x86-64 baseline. Compiled with the options of
// pair_sweep.cpp (no fused multiply-adds: every instance rounds as the scalar reference does).
#include <algorithm>
#include <cmath>

#include "dem_mobility/core/dem/dem_energy.h"
#include "dem_mobility/core/dem/pair_sweep.h"

namespace dem_mobility::core {

namespace {

using pair_kernels::InstanceOf;
using pair_kernels::kBlock;
using pair_kernels::kPad;

// The scalar reference: each live slot's pairs one after the other, those out of reach before and
// after the change (no overlap either way) and those of two unchanged ends skipped.
void PlasticExchangeScalar(const SoilContactLaw& law, double D, int threads, const ParticleStore& ps,
                           const NeighbourList& lists, const PlasticChange* rec, double* de) {
  const int n = ps.slots();
  const int* partners = lists.partners().data();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    if (ps.live(i)) {
      const PlasticChange& ri = rec[i];
      const bool ci = ri.p1 != ri.p0;
      const int end = lists.end(i);
      for (int k = lists.begin(i); k < end; ++k) {
        const PlasticChange& rj = rec[partners[k]];
        if (!ci && rj.p1 == rj.p0) continue;
        const double p1 = ri.p1 + rj.p1, p0 = ri.p0 + rj.p0;
        const double reach = D - std::min(p1, p0);
        const double r2 = (ri.x - rj.x).squaredNorm();
        if (!(reach > 0.0) || r2 >= reach * reach) continue;
        const double gap = D - std::sqrt(r2);
        sum += NormalEnergy(law, gap - p1, std::min(ri.a1, rj.a1)) - NormalEnergy(law, gap - p0, std::min(ri.a0, rj.a0));
      }
    }
    de[i] = sum;
  }
}

struct LedgerConstants {
  double D, k_n, d0, dp, inv_dp, inv_d0_dp;
};

// One block's lanes: the pair's separation, its plastic sums and adhesions after (1) and before (0)
// the change, and the energy it moved.
struct alignas(64) LedgerBlock {
  double rx[kBlock], ry[kBlock], rz[kBlock];
  double p1[kBlock], p0[kBlock], a1[kBlock], a0[kBlock];
  double de[kBlock];
};

// The reference's operations on lanes [0, n), its skips as selects of +0 (which changes no sum: a
// slot's sum starts at +0 and so is never -0; a pair of two unchanged ends moves exactly 0).
template <bool kAdhesion>
[[gnu::always_inline]] inline void LedgerLaw(const LedgerConstants& law, int n, LedgerBlock* __restrict b) {
  const LedgerConstants c = law;
  for (int l = 0; l < n; ++l) {
    const double rx = b->rx[l], ry = b->ry[l], rz = b->rz[l];
    const double r2 = (rx * rx + ry * ry) + rz * rz;
    const double p1 = b->p1[l], p0 = b->p0[l];
    const double reach = c.D - std::min(p1, p0);
    const bool in = (reach > 0.0) & (r2 < reach * reach);
    const double gap = c.D - std::sqrt(r2);
    const double after = NormalEnergyOf<kAdhesion>(c.k_n, c.d0, c.dp, c.inv_dp, c.inv_d0_dp, gap - p1, b->a1[l]);
    const double before = NormalEnergyOf<kAdhesion>(c.k_n, c.d0, c.dp, c.inv_dp, c.inv_d0_dp, gap - p0, b->a0[l]);
    b->de[l] = in ? after - before : 0.0;
  }
}

[[gnu::always_inline]] inline void GatherLedgerLanes(const PlasticChange* rec, const int* nbr, int i, int k0, int m,
                                                     int lane0, LedgerBlock* b) {
  const PlasticChange& ri = rec[i];
  for (int l = 0; l < m; ++l) {
    const PlasticChange& rj = rec[nbr[k0 + l]];
    const int q = lane0 + l;
    b->rx[q] = ri.x[0] - rj.x[0];
    b->ry[q] = ri.x[1] - rj.x[1];
    b->rz[q] = ri.x[2] - rj.x[2];
    b->p1[q] = ri.p1 + rj.p1;
    b->p0[q] = ri.p0 + rj.p0;
    b->a1[q] = std::min(ri.a1, rj.a1);
    b->a0[q] = std::min(ri.a0, rj.a0);
  }
}

// Slots [begin, end): their pairs in blocks of consecutive slots (as the sweep's), each slot's lanes
// then summed in list order; the partners' records of the slot kAhead on fetched meanwhile.
template <bool kAdhesion>
[[gnu::always_inline]] inline void LedgerRangeOf(const LedgerConstants& c, const SlotState* state, const int* nbr_begin,
                                                 const int* nbr_end, const int* nbr, const PlasticChange* rec,
                                                 int begin, int end, double* de) {
  constexpr int kAhead = 5;
  LedgerBlock b;
  int slots[kBlock];
  int lanes = 0, count = 0;
  auto law = [&](int m) __attribute__((always_inline)) {
    const int n = (m + kPad - 1) / kPad * kPad;
    for (int l = m; l < n; ++l) {  // padding: two diameters apart, out of reach
      b.rx[l] = b.ry[l] = b.rz[l] = 2.0 * c.D;
      b.p1[l] = b.p0[l] = b.a1[l] = b.a0[l] = 0.0;
    }
    LedgerLaw<kAdhesion>(c, n, &b);
  };
  auto flush = [&]() __attribute__((always_inline)) {
    if (count == 0) return;
    law(lanes);
    int lane0 = 0;
    for (int s = 0; s < count; ++s) {
      const int i = slots[s], m = nbr_end[i] - nbr_begin[i];
      double sum = 0.0;
      for (int l = 0; l < m; ++l) sum += b.de[lane0 + l];
      de[i] = sum;
      lane0 += m;
    }
    lanes = count = 0;
  };
  for (int i = begin; i < end; ++i) {
    if (i + kAhead < end)
      for (int k = nbr_begin[i + kAhead]; k < nbr_end[i + kAhead]; ++k) __builtin_prefetch(&rec[nbr[k]], 0, 3);
    if (state[i] == SlotState::kFree) {
      de[i] = 0.0;
      continue;
    }
    const int m = nbr_end[i] - nbr_begin[i];
    if (m > kBlock) {  // rare: on its own, block after block
      flush();
      double sum = 0.0;
      for (int k0 = nbr_begin[i]; k0 < nbr_end[i]; k0 += kBlock) {
        const int mb = std::min(kBlock, nbr_end[i] - k0);
        GatherLedgerLanes(rec, nbr, i, k0, mb, 0, &b);
        law(mb);
        for (int l = 0; l < mb; ++l) sum += b.de[l];
      }
      de[i] = sum;
      continue;
    }
    if (lanes + m > kBlock || count == kBlock) flush();
    GatherLedgerLanes(rec, nbr, i, nbr_begin[i], m, lanes, &b);
    slots[count++] = i;
    lanes += m;
  }
  flush();
}

using LedgerFunction = void (*)(const LedgerConstants&, bool, const SlotState*, const int*, const int*, const int*,
                                const PlasticChange*, int, int, double*);

[[gnu::always_inline]] inline void LedgerRangeBody(const LedgerConstants& c, bool adhesion, const SlotState* state,
                                                   const int* nbr_begin, const int* nbr_end, const int* nbr,
                                                   const PlasticChange* rec, int begin, int end, double* de) {
  if (adhesion)
    LedgerRangeOf<true>(c, state, nbr_begin, nbr_end, nbr, rec, begin, end, de);
  else
    LedgerRangeOf<false>(c, state, nbr_begin, nbr_end, nbr, rec, begin, end, de);
}
__attribute__((target("arch=x86-64-v4"))) void LedgerRangeAvx512(const LedgerConstants& c, bool adhesion,
                                                                  const SlotState* state, const int* nbr_begin,
                                                                  const int* nbr_end, const int* nbr,
                                                                  const PlasticChange* rec, int begin, int end,
                                                                  double* de) {
  LedgerRangeBody(c, adhesion, state, nbr_begin, nbr_end, nbr, rec, begin, end, de);
}
__attribute__((target("arch=x86-64-v3"))) void LedgerRangeAvx2(const LedgerConstants& c, bool adhesion,
                                                                const SlotState* state, const int* nbr_begin,
                                                                const int* nbr_end, const int* nbr,
                                                                const PlasticChange* rec, int begin, int end,
                                                                double* de) {
  LedgerRangeBody(c, adhesion, state, nbr_begin, nbr_end, nbr, rec, begin, end, de);
}
void LedgerRangeBaseline(const LedgerConstants& c, bool adhesion, const SlotState* state, const int* nbr_begin,
                         const int* nbr_end, const int* nbr, const PlasticChange* rec, int begin, int end,
                         double* de) {
  LedgerRangeBody(c, adhesion, state, nbr_begin, nbr_end, nbr, rec, begin, end, de);
}

}  // namespace

void PlasticExchangeEnergies(const SoilContactLaw& law, double diameter, int threads, const ParticleStore& ps,
                             const NeighbourList& lists, const PlasticChange* rec, double* de, PairKernel kernel) {
  const LedgerFunction range = InstanceOf<LedgerFunction>(kernel, LedgerRangeAvx512, LedgerRangeAvx2, LedgerRangeBaseline);
  if (!range) return PlasticExchangeScalar(law, diameter, threads, ps, lists, rec, de);
  const LedgerConstants c{diameter, law.k_n, law.d0, law.dp, law.inv_dp, law.inv_d0_dp};
  const bool adhesion = law.cohesion && law.dp > 0.0;
  const int n = ps.slots();
  constexpr int kChunk = 1024;  // slots per task (each slot's sum is its own: any split gives the same sums)
  const int chunks = (n + kChunk - 1) / kChunk;
  const SlotState* state = ps.state.data();
  const int *nbr_begin = lists.list_begin().data(), *nbr_end = lists.list_end().data(), *nbr = lists.partners().data();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int t = 0; t < chunks; ++t)
    range(c, adhesion, state, nbr_begin, nbr_end, nbr, rec, t * kChunk, std::min(n, (t + 1) * kChunk), de);
}

}  // namespace dem_mobility::core
