// A soil's strength: its cohesion factor f (paper section 2.3, eq. 15) and the cone index it stands
// for. What a user asks for is a cone index; f is internal to the law. This is the one place where
// a requested cone index becomes f (through the calibration table of the particles' size and
// friction: CI(f) depends on both, calibration.h), and where f's limits are checked. The cone
// penetrometer and the soil bin (DemSoilParams: the single-wheel rig and the dem_soil terrain with
// its moving patch) read their soil's strength through it.
#pragma once

#include <limits>
#include <memory>
#include <string>

#include "dem_mobility/core/soil/calibration.h"

namespace dem_mobility::core {

class YamlReader;

struct SoilStrength {
  /// The range of f a soil takes: the paper's 0.05 up to 40. The paper stops at 12, where its soil
  /// reads 242 psi; ours needs f of 20-30 for that at the paper's cone speed (docs/cone-penetrometer.md),
  /// and finer particles read lower at the same f. A level whose step cannot follow the stiffer
  /// adhesion ramp of a large f is refused by the time-step guard, naming the step it needs.
  static constexpr double kMinCohesionFactor = 0.05, kMaxCohesionFactor = 40.0;

  double cohesion_factor = 1.0;  ///< f
  /// [psi] the cone index asked for (`cone_index`), NaN when f was given (`cohesion_factor`)
  double requested_cone_index_psi = std::numeric_limits<double>::quiet_NaN();
  std::string calibration_file;  ///< `calibration`: a table or a directory of tables ("" : none)
  /// The table f came from, or (f given, `name_ci_of_f`) the one that names f's cone index; none
  /// when there is no table at this particle size and friction.
  std::shared_ptr<const CiCalibration> calibration;
  std::string no_table_reason;   ///< why no table names f's cone index (f given, no table found)

  /// Reads `cone_index` or `cohesion_factor`, and `calibration`, from `y` for particles of
  /// `particle_diameter` [m] and inter-particle `friction`. With f given and `name_ci_of_f`, the
  /// table at this size (if there is one) is loaded to name the cone index f stands for.
  /// ConfigError names the file and the key (cone_index outside the table, f outside
  /// [kMinCohesionFactor, kMaxCohesionFactor], no table to turn a cone index into f, both keys).
  static SoilStrength Read(const YamlReader& y, double particle_diameter, double friction, bool name_ci_of_f);

  /// The cone index the soil stands for [psi]: the requested one, or the table's for f (NaN
  /// without a table, or with f outside it).
  double ConeIndex() const;
};

}  // namespace dem_mobility::core
