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

/// Whether live slot i trips the state watchdog: a non-finite position or velocity, or a move of
/// more than `half_skin` in a step of `dt`. (The solver tests every slot in its parallel passes and
/// reports the lowest that trips: the error a serial scan would stop at.)
inline bool StateTrips(const ParticleStore& ps, int i, double dt, double half_skin) {
  return !(ps.x[i].allFinite() && ps.v[i].allFinite()) || ps.v[i].norm() * dt > half_skin;
}
/// Throws the state watchdog's SimulationError for slot i (which trips it), naming the step, the
/// particle's ID and the quantity.
[[noreturn]] void ReportStateTrip(const ParticleStore& ps, int i, double dt, double half_skin, long step, double time);

/// Whether live slot i trips the overlap watchdog: an overlap beyond `limit` [m] or a non-finite force.
inline bool OverlapTrips(const ParticleStore& ps, int i, double limit) {
  return ps.overlap[i] > limit || !ps.f[i].allFinite();
}
/// Throws the overlap watchdog's SimulationError for slot i (limit: `max_overlap` diameters).
[[noreturn]] void ReportOverlapTrip(const ParticleStore& ps, int i, double diameter, double max_overlap, long step,
                                    double time);

}  // namespace dem_mobility::core
