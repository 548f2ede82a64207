#include "dem_mobility/core/dem/dem_energy.h"

#include <algorithm>
#include <cmath>

namespace dem_mobility::core {

double PairEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists, int i, int k) {
  // the elastic energy stored in one contact: its normal branches (repulsion, and the adhesion
  // triangle's potential, zero out of contact) and its anchor spring
  const SoilContactLaw& law = *e.law;
  const int j = lists.partners()[k];
  const double d = (e.diameter - (ps.x[i] - ps.x[j]).norm()) - (ps.plastic[i] + ps.plastic[j]);
  const double fmax = std::min(ps.adhesion_max[i], ps.adhesion_max[j]);
  const double u = lists.touching()[k] ? 0.5 * law.friction.k_t * lists.histories()[k].spring.squaredNorm() : 0.0;
  return u + NormalEnergy(law, d, fmax);
}

EnergyReport MechanicalEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists) {
  EnergyReport r;
  for (int i = 0; i < ps.slots(); ++i) {
    if (!ps.live(i)) continue;
    r.kinetic += 0.5 * e.mass * ps.v[i].squaredNorm();
    r.gravitational -= e.mass * e.gravity.dot(ps.x[i]);
    for (int k = lists.begin(i); k < lists.end(i); ++k) r.elastic += PairEnergy(e, ps, lists, i, k);
  }
  return r;
}

double ParticleEnergy(const DemEnergyTerms& e, const ParticleStore& ps, const NeighbourList& lists, int i) {
  double u = 0.5 * e.mass * ps.v[i].squaredNorm() - e.mass * e.gravity.dot(ps.x[i]);
  for (int k = lists.begin(i); k < lists.end(i); ++k) u += PairEnergy(e, ps, lists, i, k);
  for (int j : lists.Candidates(ps, ps.x_built[i]))
    if (j != i)
      for (int k = lists.begin(j); k < lists.end(j); ++k)
        if (lists.partners()[k] == i) u += PairEnergy(e, ps, lists, j, k);
  return u;
}

}  // namespace dem_mobility::core
