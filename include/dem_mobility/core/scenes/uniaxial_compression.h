// The piston-cylinder uniaxial compression test (paper section 2.3, fig. 9): soil poured into a
// rigid cylinder is compressed by a piston at increasing pressures and unloaded again; the bulk
// density at each pressure, during loading and unloading, shows the soil's plastic compaction.
#pragma once

#include <string>
#include <vector>

#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;

struct CompressionParams {
  std::string file;
  SoilParams soil;                 ///< with particle_diameter and cohesion_factor applied
  double particle_diameter = 0.03, cylinder_diameter = 0.3, soil_depth = 0.2;  ///< [m]
  double time_step = 4e-5, settle_time = 0.4, hold_time = 0.05;  ///< [s]
  double piston_speed = 0.2;       ///< [m/s] most the piston moves
  std::vector<double> loading;     ///< pressures [Pa], increasing
  std::vector<double> unloading;   ///< pressures [Pa], decreasing, below the last loading one
  double solid_fraction = 0.58;
  int threads = 1;
  unsigned seed = 1;
  static CompressionParams Read(const YamlReader& y);
};

struct CompressionPoint {
  double pressure = 0.0;  ///< mean over the hold [Pa]
  double density = 0.0;   ///< bulk: particle mass / (area x piston height) [kg/m^3]
};

struct CompressionResult {
  int particles = 0;
  double density_poured = 0.0;     ///< before the piston [kg/m^3]
  std::vector<CompressionPoint> loading, unloading;
  double density_released = 0.0;   ///< after the piston is gone (free surface) [kg/m^3]
  double sim_time = 0.0, wall_time = 0.0;
  long steps = 0;
  std::string error;
};

/// Runs the test; numerical failures end it with `error` set and what was measured so far.
CompressionResult RunUniaxialCompression(const CompressionParams& p);
/// The result file (the one schema: scene, kind, status, error, then the figures).
ResultFile CompressionResultFile(const CompressionResult& r, const CompressionParams& p);

}  // namespace dem_mobility::core
