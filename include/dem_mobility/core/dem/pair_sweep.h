// The DEM pair forces: every listed pair evaluated once, its force added to both particles. The
// slabs are swept by colour, the even slabs in parallel and then the odd ones (see
// neighbour_list.h), each slab by one thread in ascending slot order: every particle's force is
// summed in the same order for any number of threads.
#pragma once

#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

/// Adds the pair forces to ps->f (set beforehand to the weights) and records each particle's
/// largest repulsion, tension and overlap (reset beforehand); updates the contact histories.
void SweepPairs(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                NeighbourList* lists);

}  // namespace dem_mobility::core
