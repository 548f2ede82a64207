// The terrain side of the co-simulation: a model that turns wheel states into wheel wrenches.
// The rigid polygonal road is one model; the DEM soil is another, behind the same interface, so
// one terrain nodelet serves either.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/cosim/exchange.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility {

class TerrainModel {
 public:
  virtual ~TerrainModel() = default;
  /// The model's name in the terrain file (`model:`), e.g. "rigid_road".
  virtual std::string kind() const = 0;
  /// Wrenches on the wheels for exchange `step` at time `t` from their states. Called once per
  /// exchange in increasing step order (models with history, such as friction anchors, rely on it).
  virtual void Compute(long step, double t, const std::vector<WheelState>& states,
                       std::vector<WheelWrench>* wrenches) = 0;
  /// The surface as triangles (world frame), for display.
  virtual const TriMesh& Surface() const = 0;
};

/// Builds the terrain described by `terrain_file` for the wheels of the vehicle in `vehicle_file`
/// (their tire geometry). Throws ConfigError naming file and key of bad input.
std::unique_ptr<TerrainModel> LoadTerrainModel(const std::string& terrain_file, const std::string& vehicle_file);

}  // namespace dem_mobility
