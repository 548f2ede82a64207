// Prepared soils kept in a folder: preparing a DEM soil (pour, lid, release) takes minutes to hours
// and is deterministic, so a soil this build has prepared from the same terrain file (overrides
// applied), soil file, calibration tables and tire is read back instead of prepared again, bit for
// bit the state the preparation gives. The folder is the caller's (dm_run_scene's
// --prepared-soil-cache, the terrain nodelet's ~prepared_soil_cache, a test's); the core reads no
// environment.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/common/input_files.h"

namespace dem_mobility::core {

class YamlReader;
class StateReader;
class StateWriter;
struct TerrainVehicle;

class PreparedSoilCache {
 public:
  explicit PreparedSoilCache(std::string folder) : folder_(std::move(folder)) {}
  /// The file of a soil in the folder: named by the fingerprint of everything its preparation
  /// depends on (the terrain file `y` with its overrides, the files its reading read, the tire,
  /// this build).
  std::string PathOf(const YamlReader& y, const std::vector<InputFile>& files, const TerrainVehicle& vehicle) const;
  /// Reads the soil kept at `path` through `load` (which builds the terrain from its state and
  /// reads it all); false when there is none, or when it does not read (a warning on stderr: the
  /// caller prepares it again).
  static bool Read(const std::string& path, const std::function<void(StateReader&)>& load);
  /// Keeps the state `save` writes at `path` (written whole through a temporary file); a soil that
  /// cannot be kept is a warning on stderr, not an error (the run goes on without the cache).
  static void Keep(const std::string& path, const std::function<void(StateWriter&)>& save);

 private:
  std::string folder_;
};

}  // namespace dem_mobility::core
