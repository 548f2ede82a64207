#include "dem_mobility/core/dem/dem_watchdogs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

TimeStepLimit DemCriticalTimeStep(const SoilParams& soil, double mass, int max_coordination) {
  const double z = max_coordination;
  double k = std::max(soil.NormalStiffness(), soil.TangentialStiffness());
  std::string branch = soil.NormalStiffness() >= soil.TangentialStiffness() ? "repulsion" : "tangential spring";
  if (soil.cohesion && soil.adhesion_peak > 0.0) {
    double s_max = 0.0;
    for (double s : soil.adhesion_stress_vs_plastic_strain.y()) s_max = std::max(s_max, s);
    const double k_adh = soil.cohesion_factor * s_max * soil.Area() / (soil.adhesion_peak * soil.diameter);
    if (k_adh > k) {
      k = k_adh;
      branch = "adhesion ramp";
    }
  }
  const double omega = std::sqrt(z * k / mass);
  const double zeta = z * soil.NormalDamping() / (2.0 * std::sqrt(z * k * mass));
  TimeStepLimit lim;
  lim.dt_crit = CriticalStep(omega, zeta);
  lim.element = "soil particle contact";
  lim.detail = detail::Concat(branch, " stiffness ", k, " N/m from ", max_coordination, " neighbours on a particle of ",
                              mass, " kg (damping ratio ", zeta, ")");
  return lim;
}

void ReportStateTrip(const ParticleStore& ps, int i, double dt, double half_skin, long step, double time) {
  const Eigen::Vector3d& x = ps.x[i];
  const Eigen::Vector3d& v = ps.v[i];
  if (!(x.allFinite() && v.allFinite()))
    throw SimulationError(detail::Concat("DEM step ", step, " (t = ", time, " s): particle ", ps.id_of_slot[i],
                                         " has a non-finite state (x = ", x.transpose(), ", v = ", v.transpose(),
                                         "); the time step is too large or an input is NaN"));
  const double move = v.norm() * dt;
  throw SimulationError(detail::Concat("DEM step ", step, " (t = ", time, " s): particle ", ps.id_of_slot[i], " moved ",
                                       move, " m in one step, more than half the skin (", half_skin,
                                       " m); its speed is ", v.norm(), " m/s"));
}

void ReportOverlapTrip(const ParticleStore& ps, int i, double diameter, double max_overlap, long step, double time) {
  throw SimulationError(detail::Concat("DEM step ", step, " (t = ", time, " s): particle ", ps.id_of_slot[i],
                                       !ps.f[i].allFinite() ? " has a non-finite force" : " overlaps a neighbour or a wall by ",
                                       ps.overlap[i] / diameter, " of the diameter (limit ", max_overlap, ")"));
}

}  // namespace dem_mobility::core
