// The cone index calibration (paper section 3, table 3): the table that turns a requested cone
// index (CI, psi) into the cohesion factor f of the soil, for one particle size and one
// inter-particle friction. CI(f) depends on the particle size (docs/cone-penetrometer.md), so a
// table holds for the particle diameter its cone sweep was run at, and a scene must pick the table
// of its own particles (LoadFor). Written by dm-calibrate (python/dem_mobility_tools/calibration) from a sweep of cone
// penetrometer runs (several seeds per f); the soil scenes read it.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace dem_mobility::core {

class ResultFile;
class YamlReader;

struct CiCalibration {
  std::string file;
  double particle_diameter = 0.0;      ///< [m] the particles the sweep was run with
  double friction = 0.0;               ///< the inter-particle mu it holds for
  std::string level;                   ///< fidelity level of the runs behind it
  std::vector<double> ci, f;           ///< table rows, CI strictly increasing, f increasing
  double band = 0.0;                   ///< relative CI scatter of the runs about the fit (rms)

  /// The measured points behind the table: per cohesion factor, the mean CI over the seeds and
  /// its scatter (sample standard deviation over the seeds; NaN for a single seed).
  struct Point {
    double f = 0.0, ci_mean = 0.0, ci_std = 0.0;
    int seeds = 0;
  };
  std::vector<Point> points;

  /// Where the table came from: git commit, seeds, soil file and its sha256, scene file, date and
  /// the conditions of the runs (container diameter, soil depth, cone speed, ...), as text.
  std::vector<std::pair<std::string, std::string>> provenance;
  std::vector<int> seeds;              ///< provenance.seeds

  /// The table level's relative CI error against the finest level that was run (`level`);
  /// `relative` is NaN when no finer level was run, and `note` then says so.
  struct ErrorVsFinest {
    std::string level;
    double relative = 0.0;
    std::string note;
  } error_vs_finest;

  /// Reads a calibration file; ConfigError names file and key (a missing particle_diameter or
  /// provenance, rows not increasing, ...).
  static CiCalibration Read(const YamlReader& y);
  static CiCalibration Load(const std::string& path);
  /// The table for particles of `particle_diameter` [m] (relative tolerance 1e-6) and the
  /// inter-particle `friction`. `path` is one table file or a directory of tables (*.yaml). Throws
  /// ConfigError naming the file or directory, the key particle_diameter (or friction) and the
  /// tables available (their diameter and friction) when none matches, or when two do.
  static CiCalibration LoadFor(const std::string& path, double particle_diameter, double friction);

  /// Writes into a result which table it used: calibration_table (path), calibration_level,
  /// calibration_particle_diameter, calibration_friction, calibration_seeds (fewest per point),
  /// calibration_band (the runs' relative rms scatter about the fit),
  /// calibration_points_relative_std_max (the largest std over the seeds of a point, relative to its
  /// mean; a text when no point has two seeds), calibration_error_vs_finest (relative, or a text
  /// saying why it is not known) and calibration_finest_level.
  void Describe(ResultFile* r) const;

  /// The fewest seeds behind a point of the table.
  int MinSeeds() const;
  /// f for a requested CI, interpolated in the table; ConfigError outside the table's range.
  double CohesionFactor(double ci_psi) const;
  /// The CI the table predicts for f (the inverse interpolation); ConfigError outside its range.
  double ConeIndex(double f) const;
};

}  // namespace dem_mobility::core
