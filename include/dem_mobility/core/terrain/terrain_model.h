// The terrain side of the co-simulation: a model that turns wheel states into wheel wrenches. Its
// lifecycle follows a co-simulation terrain's (as Chrono's does): at each exchange it is
// synchronized with the wheel states of that step, returns the wrenches of that state, and then
// advances to the next exchange, with sub-steps of its own if it needs them (a DEM soil). The
// rigid polygonal road is one model; the DEM soil is another, behind the same interface, so one
// terrain nodelet and the in-process runner serve either.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/cosim/exchange.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

class YamlReader;

class TerrainModel {
 public:
  virtual ~TerrainModel() = default;
  virtual const TerrainDescription& description() const = 0;
  /// Exchange `step` at time `t`: the wheels are where `states` say. Called once per exchange in
  /// increasing step order (models with history, such as friction anchors, rely on it).
  virtual void Synchronize(long step, double t, const std::vector<WheelState>& states) = 0;
  /// The wrenches on the wheels in the synchronized state.
  virtual void GetWrenches(std::vector<WheelWrench>* wrenches) const = 0;
  /// Advances the terrain by `dt` to the next exchange (0 at the opening exchange). A rigid
  /// terrain has nothing to advance.
  virtual void Advance(double dt) = 0;
  /// The surface as triangles (world frame), for display.
  virtual const TriMesh& Surface() const = 0;
};

/// What a terrain needs of the vehicle: its wheels' geometry.
struct TerrainVehicle {
  TireGeometry tire;
  int wheels = 4;
};

/// One kind of terrain: the `model:` key of its files, a factory and a describer.
struct TerrainKind {
  std::string model;
  std::string what;  ///< one line for messages and listings
  std::function<std::unique_ptr<TerrainModel>(const YamlReader& file, const TerrainVehicle& vehicle)> make;
  std::function<TerrainDescription(const YamlReader& file)> describe;
};

/// The terrain kinds there are.
const std::vector<TerrainKind>& TerrainKinds();

/// Builds the terrain described by `terrain_file` for the wheels of `vehicle`. Throws ConfigError
/// naming file and key of bad input (an unknown `model:` lists the known ones).
std::unique_ptr<TerrainModel> LoadTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle);
/// What `terrain_file` describes (model and cone index), without building it.
TerrainDescription DescribeTerrain(const std::string& terrain_file);

}  // namespace dem_mobility::core
