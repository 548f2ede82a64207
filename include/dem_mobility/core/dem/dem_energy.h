// The DEM's energies: kinetic, gravitational and the elastic energy stored in the contacts (the
// repulsion, the adhesion triangle's potential and the anchor springs), and the ledger of what
// walls, added and removed particles and gravity changes put in since Finalize.
#pragma once

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
/// The normal branches' energy (repulsion, the adhesion triangle) of a contact of overlap `d` (the
/// plastic deformations taken off) and largest adhesion `fmax`: the part the law's plastic changes
/// move. Inline: the plastic ledger calls it twice for every listed pair of a changed particle.
inline double NormalEnergy(const SoilContactLaw& law, double d, double fmax) {
  if (!(d > 0.0)) return 0.0;
  const double d0 = law.d0, dp = law.dp;
  double u = 0.0;
  if (d > d0) u += 0.5 * law.k_n * (d - d0) * (d - d0);
  if (law.cohesion && fmax > 0.0 && dp > 0.0) {
    const double a = d < d0 ? d : d0;
    u -= a <= dp ? 0.5 * fmax * a * a / dp : 0.5 * fmax * dp + fmax * (a - dp) - 0.5 * fmax * (a - dp) * (a - dp) / (d0 - dp);
  }
  return u;
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
