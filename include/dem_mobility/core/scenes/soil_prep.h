// Pieces of the soil preparation that the scenes share (paper sections 3 and 4.2): the loose
// lattice the particles are poured from, and the lid that consolidates them at a pressure.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility {

class YamlReader;

/// Positions of `count` particles of diameter d on a jittered square lattice (spacing `spacing`
/// d) over the floor z = 0, layer after layer, inside the region where `inside(x, y)` holds
/// (checked for the particle's centre). Deterministic for a seed.
std::vector<Eigen::Vector3d> PourLattice(int count, double d, double spacing, const Eigen::Vector2d& lo,
                                         const Eigen::Vector2d& hi,
                                         const std::function<bool(double, double)>& inside, unsigned seed);

/// A lid driven down onto the particles at a speed proportional to the force it still lacks of
/// `target` (up to `max_speed`), so that it settles on the target without overshoot: its loop gain
/// per step, max_speed dt k_layer / target (k_layer: the stiffness of one layer of contacts under
/// the lid), is capped at 0.5.
class LidPress {
 public:
  LidPress(double target_force, double max_speed, double dt, double k_layer);
  /// Lid speed along z for the force the particles now put on it (fz > 0: pushing it up).
  double Velocity(double fz) const;
  double target() const { return target_; }
  double max_speed() const { return v_max_; }

 private:
  double target_, v_max_;
};

/// A cylindrical container (axis z, floor at z = 0) with `count` particles of the system's
/// diameter poured into it from a jittered lattice, and a lid disk just above them.
struct CylinderBed {
  int floor = -1, lid = -1;  ///< wall indices
  double wall_height = 0.0;  ///< of the container's side
};
CylinderBed AddCylinderBed(DemSystem* s, double radius, int count, int segments, unsigned seed);

/// The `threads` key of a scene (OpenMP threads, default 1, in [1, 256]).
int ReadThreads(const YamlReader& y);

/// Checks that `y` is a scene file of `kind` (its `scene:` key) and reads its soil file (`soil:`,
/// relative to the scene file). ConfigError names the file and key.
SoilParams ReadSceneSoil(const YamlReader& y, const std::string& kind);

/// Height of the highest particle centre (0 without particles).
double TopParticle(const DemSystem& s);

}  // namespace dem_mobility
