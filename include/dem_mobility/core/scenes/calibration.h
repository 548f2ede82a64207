// The cone index calibration (paper section 3, table 3): the table that turns a requested cone
// index (CI, psi) into the cohesion factor f of the soil, for one inter-particle friction. Written
// by scripts/calibrate_cone_index.py from a sweep of cone penetrometer runs; the soil scenes read it.
#pragma once

#include <string>
#include <vector>

namespace dem_mobility::core {

class YamlReader;

struct CiCalibration {
  std::string file;
  double friction = 0.0;               ///< the inter-particle mu it holds for
  std::string level;                   ///< fidelity level of the runs behind it
  std::vector<double> ci, f;           ///< table rows, CI strictly increasing, f increasing
  double band = 0.0;                   ///< relative CI scatter of the runs about the fit (rms)

  /// Reads a calibration file; ConfigError names file and key (rows not increasing, ...).
  static CiCalibration Read(const YamlReader& y);
  static CiCalibration Load(const std::string& path);
  static CiCalibration LoadFor(const std::string& path, double particle_diameter, double friction);
  void Describe(class ResultFile* r) const;
  /// f for a requested CI, interpolated in the table; ConfigError outside the table's range.
  double CohesionFactor(double ci_psi) const;
  /// The CI the table predicts for f (the inverse interpolation); ConfigError outside its range.
  double ConeIndex(double f) const;
};

}  // namespace dem_mobility::core
