// INTERIM (removed when the per-particle-size calibration lands): LoadFor and Describe over the
// old single-size tables, so the wheel rig builds meanwhile.
#include <cmath>
#include <filesystem>

#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/scenes/calibration.h"

namespace dem_mobility::core {

CiCalibration CiCalibration::LoadFor(const std::string& path, double, double friction) {
  if (!std::filesystem::is_directory(path)) return Load(path);
  for (const auto& e : std::filesystem::directory_iterator(path)) {
    const CiCalibration c = Load(e.path().string());
    if (std::abs(c.friction - friction) < 1e-9) return c;
  }
  throw ConfigError(path + ": no table for mu " + std::to_string(friction));
}

void CiCalibration::Describe(ResultFile* r) const {
  r->Set("calibration_table", file);
  r->Set("calibration_level", level);
}

}  // namespace dem_mobility::core
