// Energy bookkeeping, the same report for the multibody system and the DEM particles.
#pragma once

namespace dem_mobility::core {

struct EnergyReport {
  double kinetic = 0.0;
  double gravitational = 0.0;  ///< -m g . x summed
  double elastic = 0.0;        ///< penalty springs, springs, contacts
  double Total() const { return kinetic + gravitational + elastic; }
  // the ledger since the start (models that keep one; zero otherwise)
  double wall_work = 0.0;      ///< work of moving walls on the system (trapezoidal in time)
  double exchanged = 0.0;      ///< energy of parts added less that of parts removed, and of gravity changes
  double dissipated = 0.0;     ///< wall_work + exchanged - (Total() - Total() at the start)
};

}  // namespace dem_mobility::core
