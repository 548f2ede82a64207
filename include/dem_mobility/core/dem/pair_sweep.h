// The DEM pair forces: every listed pair evaluated once, its force added to both particles. The
// slabs are swept as if by colour, the even slabs in parallel and then the odd ones (see
// neighbour_list.h; each odd slab in fact waits only for the two even slabs beside it), each slab
// by one thread in ascending slot order: every particle's force is summed in the same order for any
// number of threads.
//
// Two kernels compute the same law:
//  - the scalar one, the soil law's per-pair functions (SoilContactLaw::Normal, Tangential) one
//    contact after the other: the reference;
//  - the vector one: the pairs of consecutive particles in blocks of 32 lanes (structure of arrays
//    gathered from each partner's one-cache-line hot record and from the contact histories), the
//    law written without branches over the block's lanes so that the compiler vectorises it, then
//    the forces scattered particle after particle in the scalar kernel's order, into one
//    cache-line record of sums per partner (ps->sums; the scalar kernel sums into it too). It is
//    compiled three times, for x86-64-v4 (AVX-512), x86-64-v3 (AVX2, FMA) and the x86-64 baseline
//    (SSE2), and the best the CPU has is taken at run time
//    (kAuto). Floating-point contraction is off in that file and every sum is associated as
//    Eigen's are, so all of its instances give the scalar kernel's results bit for bit.
#pragma once

#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

enum class PairKernel {
  kAuto,             ///< the vector kernel for the best instruction set the CPU has
  kVectorAvx512,     ///< the vector kernel, x86-64-v4 (AVX-512F/VL/DQ/BW)
  kVectorAvx2,       ///< the vector kernel, x86-64-v3 (AVX2, FMA)
  kVectorBaseline,   ///< the vector kernel, x86-64 baseline (SSE2)
  kScalar,           ///< the scalar reference
};

/// kAuto resolved for this CPU; a vector instance the CPU cannot run is refused (ConfigError).
PairKernel ResolvePairKernel(PairKernel requested);
/// "vector-avx512", "vector-avx2", "vector-baseline", "scalar" (kAuto: what it resolves to).
const char* PairKernelName(PairKernel kernel);

/// Adds the pair forces to each slot's sums (ps->sums: its force, its plastic drive, soil_law.h's
/// PlasticDrive, and its largest overlap, started beforehand) and updates the contact histories. The slots' records are
/// packed beforehand (ParticleStore::SizeScratch and PackFresh: the vector kernels gather from
/// ps->hot; the scalar one reads the per-slot arrays).
void SweepPacked(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                 NeighbourList* lists, PairKernel kernel = PairKernel::kAuto);

/// SweepPacked on the per-slot arrays: adds the pair forces to ps->f and updates each particle's
/// plastic drive and largest overlap in max_repulsion, normal_sum, adhesion_reach and overlap (packs the
/// slots from them, sweeps, and unpacks).
void SweepPairs(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                NeighbourList* lists, PairKernel kernel = PairKernel::kAuto);

/// A slot's part in the plastic ledger's pass (DemSystem::set_plastic_ledger): its position, and
/// its plastic deformation and largest adhesion before (p0, a0) and after (p1, a1) the step's
/// plastic update. One cache line: a partner's record is read once per pair.
struct alignas(64) PlasticChange {
  Eigen::Vector3d x;
  double p0, a0, p1, a1;
};
static_assert(sizeof(PlasticChange) == 64, "one cache line");

/// The energy the step's plastic changes moved at fixed positions, per slot: de[i] is the sum over
/// slot i's listed pairs, in list order, of the pair's normal energy (NormalEnergy) after the change
/// less before (0 for a free slot and for a pair out of reach both before and after). The vector
/// instances run the pairs of consecutive slots in blocks, as the sweep does, and give the scalar
/// reference's sums bit for bit; each slot's sum is its own, so any number of threads gives them too.
void PlasticExchangeEnergies(const SoilContactLaw& law, double diameter, int threads, const ParticleStore& ps,
                             const NeighbourList& lists, const PlasticChange* rec, double* de,
                             PairKernel kernel = PairKernel::kAuto);

/// The benchmark's ceiling: pairs per second of the law alone on `kernel` (vector instances only),
/// on one block of 32 pairs in contact that stays in L1 (no gather, no scatter, no memory), over
/// `repetitions` evaluations on one thread.
double PairLawThroughput(PairKernel kernel, const SoilContactLaw& law, double diameter, double dt, long repetitions);

/// What the kernels' two sources share (pair_sweep.cpp, plastic_ledger_pass.cpp): the block of
/// lanes their vector kernels work on, and the choice of a vector function's compiled instance.
namespace pair_kernels {

constexpr int kBlock = 32;  // pairs per block (of one slot or of several consecutive ones)
constexpr int kPad = 8;     // a block's lanes are computed in multiples of this (one AVX-512 vector)

// Of the three compiled instances of a vector function, the one `kernel` names (kAuto resolved for
// this CPU; a kernel named outright taken as it is); nullptr for the scalar reference.
template <class F>
F InstanceOf(PairKernel kernel, F avx512, F avx2, F baseline) {
  switch (kernel == PairKernel::kAuto ? ResolvePairKernel(kernel) : kernel) {
    case PairKernel::kVectorAvx512: return avx512;
    case PairKernel::kVectorAvx2: return avx2;
    case PairKernel::kVectorBaseline: return baseline;
    default: return nullptr;
  }
}

}  // namespace pair_kernels

}  // namespace dem_mobility::core
