// The DEM's energies: kinetic, gravitational and the elastic energy stored in the contacts (the
// repulsion, the adhesion triangle's potential and the anchor springs), and the ledger of what
// walls, added and removed particles and gravity changes put in since Finalize.
#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

/// What the energy sums need besides the particles and their lists.
struct DemEnergyTerms {
  const SoilContactLaw* law;
  double diameter, mass;
  Eigen::Vector3d gravity;
};

/// The elastic energy of listed pair k of slot i.
double PairEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists, int i, int k);
/// NormalEnergy's operations, with the adhesion triangle compiled in or out (kAdhesion: the law's
/// cohesion on and dp > 0). Branch-free in `d` (both arms computed, one selected: the values a
/// branch gives): the plastic ledger runs it twice for every listed pair, on the lanes of a vector
/// block (pair_sweep.h, PlasticExchangeEnergies), and in a packed bed `d` sits about d0, where a
/// branch is mispredicted half the time.
/// `inv_dp`, `inv_d0_dp`: 1 / dp and 1 / (d0 - dp) (SoilContactLaw's, 0 where undefined): no
/// division in the ledger's lanes.
template <bool kAdhesion>
[[gnu::always_inline]] inline double NormalEnergyOf(double k_n, double d0, double dp, double inv_dp, double inv_d0_dp,
                                                    double d, double fmax) {
  const double over = std::max(d - d0, 0.0);
  double u = 0.5 * k_n * over * over;
  if constexpr (kAdhesion) {
    const double f = std::max(fmax, 0.0), a = std::min(d, d0), past = a - dp;
    const double rising = 0.5 * f * a * a * inv_dp;
    // (where a passes dp, d0 > dp: the arm of d0 == dp is never selected)
    const double falling = 0.5 * f * dp + f * past - 0.5 * f * past * past * inv_d0_dp;
    u -= a <= dp ? rising : falling;
  }
  return d > 0.0 ? u : 0.0;
}
/// The normal branches' energy (repulsion, the adhesion triangle) of a contact of overlap `d` (the
/// plastic deformations taken off) and largest adhesion `fmax`: the part the law's plastic changes
/// move.
inline double NormalEnergy(const SoilContactLaw& law, double d, double fmax) {
  return law.cohesion && law.dp > 0.0
             ? NormalEnergyOf<true>(law.k_n, law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d, fmax)
             : NormalEnergyOf<false>(law.k_n, law.d0, law.dp, law.inv_dp, law.inv_d0_dp, d, fmax);
}
/// Kinetic, gravitational and elastic energy of all live particles.
EnergyReport MechanicalEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists);
/// Slot i's kinetic and gravitational energy and that of all its pairs (what it takes away when removed).
double ParticleEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists, int i);

/// The energy put in from outside since Finalize.
struct DemLedger {
  using StateBulk = void;
  double e0 = 0.0;          ///< mechanical energy at Finalize
  double wall_work = 0.0;   ///< the walls' work on the particles (trapezoidal in time)
  double exchanged = 0.0;   ///< particles added less removed, gravity changes, and `plastic`
  /// the contact law's own changes at fixed positions: the plastic deformations and the adhesion
  /// that follows them, changed after a step (compaction takes energy, relaxation gives it back);
  /// kept only while DemSystem::set_plastic_ledger(true)
  double plastic = 0.0;
  double wall_power = 0.0;  ///< the walls' power at the last force evaluation
};

}  // namespace dem_mobility::core
