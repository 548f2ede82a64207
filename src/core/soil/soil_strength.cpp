#include "dem_mobility/core/soil/soil_strength.h"

#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

namespace {

/// Whether a soil's strength is given by its `cone_index` (true) or by its `cohesion_factor` in the
/// map `y`. Where both are there, the one an override set takes the place of the other in the file
/// (which is then read, so that it is no unknown key); both in the file, or both overridden, is
/// refused naming the file and cohesion_factor. Neither: false (the caller then needs
/// cohesion_factor).
bool SoilStrengthByConeIndex(const YamlReader& y) {
  if (!y.Has("cone_index")) return false;
  if (!y.Has("cohesion_factor")) return true;
  const bool ci = y.Overridden("cone_index");
  if (ci == y.Overridden("cohesion_factor"))
    y.Fail("cohesion_factor", std::string("and cone_index are both given") + (ci ? " by overrides" : " in the file") +
                                  ": give one of them (an override of either takes the place of the other in the file)");
  y.Double(ci ? "cohesion_factor" : "cone_index");
  return ci;
}

}  // namespace

SoilStrength SoilStrength::Read(const YamlReader& y, double particle_diameter, double friction, bool name_ci_of_f) {
  SoilStrength s;
  if (y.Has("calibration")) s.calibration_file = y.ResolvePath(y.String("calibration"));
  const bool by_ci = SoilStrengthByConeIndex(y);  // (the one an override gives, where both are there)
  if (by_ci) {
    s.requested_cone_index_psi = y.Positive("cone_index");
    if (s.calibration_file.empty()) y.Fail("calibration", "is needed to turn cone_index into f");
    try {
      auto table = std::make_shared<CiCalibration>(CiCalibration::LoadFor(s.calibration_file, particle_diameter, friction));
      s.cohesion_factor = table->CohesionFactor(s.requested_cone_index_psi);
      s.calibration = std::move(table);
    } catch (const ConfigError& e) {
      y.Fail("cone_index", e.what());
    }
  } else {
    if (!y.Has("cohesion_factor")) y.Fail("cohesion_factor", "is not set (nor is cone_index)");
    s.cohesion_factor = y.Double("cohesion_factor");
    if (name_ci_of_f && !s.calibration_file.empty()) {
      // a table at this particle size only names the CI this f stands for; without one the CI is
      // unknown (and the result says why)
      try {
        s.calibration = std::make_shared<CiCalibration>(CiCalibration::LoadFor(s.calibration_file, particle_diameter, friction));
      } catch (const ConfigError& e) {
        s.no_table_reason = e.what();
      }
    }
  }
  if (!(s.cohesion_factor >= kMinCohesionFactor && s.cohesion_factor <= kMaxCohesionFactor))
    y.Fail(by_ci ? "cone_index" : "cohesion_factor",
           "the cohesion factor f = " + detail::Concat(s.cohesion_factor) + " lies outside the range a soil takes [" +
               detail::Concat(kMinCohesionFactor) + ", " + detail::Concat(kMaxCohesionFactor) + "]");
  return s;
}

double SoilStrength::ConeIndex() const {
  if (std::isfinite(requested_cone_index_psi)) return requested_cone_index_psi;
  if (!calibration) return std::numeric_limits<double>::quiet_NaN();
  try {
    return calibration->ConeIndex(cohesion_factor);
  } catch (const ConfigError&) {
    return std::numeric_limits<double>::quiet_NaN();  // f outside the table: no CI to name
  }
}

}  // namespace dem_mobility::core
