// The DEM's guards: the critical time step of the soil contact, and the per-step watchdogs that
// stop a run (SimulationError naming the step, the particle ID and the quantity) before it blows up.
#pragma once

#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

/// The stiffest branch (repulsion k_n or the anchor spring k_t; the adhesion ramp f_max / peak
/// where it is stiffer) acting from `max_coordination` neighbours at once on a particle of `mass`.
TimeStepLimit DemCriticalTimeStep(const SoilParams& soil, double mass, int max_coordination);

/// A non-finite position or velocity, or a particle moving more than `half_skin` in a step of `dt`.
void CheckParticleStates(const ParticleStore& ps, double dt, double half_skin, long step, double time);

/// An overlap beyond `max_overlap` diameters, or a non-finite force.
void CheckParticleOverlaps(const ParticleStore& ps, double diameter, double max_overlap, long step, double time);

}  // namespace dem_mobility::core
