// The terrain side of the co-simulation: a model that turns wheel states into wheel wrenches. Its
// lifecycle follows a co-simulation terrain's (as Chrono's does): at each exchange it is
// synchronized with the wheel states of that step, returns the wrenches of that state, and then
// advances to the next exchange, with sub-steps of its own if it needs them (a DEM soil). The
// rigid polygonal road is one model; the DEM soil is another, behind the same interface, so one
// terrain nodelet and the in-process runner serve either.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

class YamlReader;
class ResultFile;
class DemSystem;
class StateWriter;
class StateReader;

/// What a terrain shows besides its surface (the ROS layer draws it): its particles, its tools
/// (walls, drawn at their poses) and a moving soil patch's sphere and box.
struct TerrainDisplay {
  const DemSystem* dem = nullptr;  ///< the particles (nullptr: none)
  std::vector<int> walls;          ///< walls of `dem` to draw (the patch's tools)
  bool patch = false;
  Eigen::Vector3d sphere_centre = Eigen::Vector3d::Zero();
  double sphere_radius = 0.0;
  double box_rear = 0.0, box_front = 0.0, box_width = 0.0, floor_z = 0.0, box_height = 0.0;
  double emitter_from = 0.0, emitter_to = 0.0;  ///< the layer the emitter fills (x)
  /// The soil's strips under the wheel tracks ([lo, hi] in y; empty: soil over the box's width)
  /// and the height of the rigid floor between and beside them.
  std::vector<std::pair<double, double>> strips;
  double strip_floor_z = 0.0;
};

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
  /// Its particles and tools, for display (a rigid terrain has none).
  virtual TerrainDisplay Display() const { return TerrainDisplay(); }
  /// The scene's gravity (a grade is a rotated gravity vector, paper section 4.3: the terrain and
  /// the soil patch are set to the grade). A terrain with mass of its own (the DEM soil) puts its
  /// particles under it from the next step on; a rigid one has nothing to put under it.
  virtual void SetGravity(const Eigen::Vector3d& /*g*/) {}
  /// Writes the terrain's own figures into a run's result (a soil's level, f, cone index and
  /// table, the moving patch's checks); a rigid terrain has none.
  virtual void Describe(ResultFile* /*r*/) const {}
  /// Its state in a checkpoint (common/state_archive.h), after the model built from the same file
  /// (LoadTerrainModel) or restored (RestoreTerrainModel): a run read back steps on bit for bit.
  virtual void SaveState(StateWriter& out) const = 0;
  virtual void LoadState(StateReader& in) = 0;
};

/// What a terrain needs of the vehicle: its wheels' geometry.
struct TerrainVehicle {
  TireGeometry tire;
  int wheels = 4;
  double track = 0.0;  ///< [m] between the wheel centres of the wider axle (0: unknown)
  double wheelbase = 0.0;  ///< [m] between the front and rear axles (0: unknown)
};

struct VehicleSpec;
/// What a terrain needs of the vehicle `spec` describes (its tire, four wheels, its track).
TerrainVehicle TerrainVehicleOf(const VehicleSpec& spec);

/// Where a terrain's preparation is (a DEM soil: its pour, the lid's consolidation, the lid's
/// retreat, the release), for a console or a log while it takes minutes or hours.
struct PreparationProgress {
  std::string phase;       ///< pour, consolidate, retreat, release, done
  double simulated = 0.0;  ///< [s] of the preparation simulated so far
  double wall = 0.0;       ///< [s] since the preparation began
  int particles = 0;
  std::string detail;      ///< what the phase is waiting for (e.g. the lid's height and pressure)
  /// One line: "consolidate: 0.631 s simulated in 2820 s, 628431 particles; lid at ...".
  std::string Line() const;
};

/// How a long preparation goes. `stop` (may be empty): called every step; once it returns true the
/// preparation stops within a step and throws Interrupted saying where it was. `progress` (may be
/// empty): called when a phase begins, about every `progress_every` wall seconds within one, and
/// when the preparation is done. `described` (may be empty): called once, as soon as the terrain
/// has read its file and knows what it is (before a long preparation), with its description.
/// `prepared_soil_cache` (may be empty): the folder of prepared soils (PreparedSoilCache) a soil is
/// read from instead of prepared, and kept in once prepared.
struct PreparationHooks {
  std::function<bool()> stop;
  std::function<void(const PreparationProgress&)> progress;
  double progress_every = 10.0;  ///< [s] of wall time
  std::function<void(const TerrainDescription&)> described;
  std::string prepared_soil_cache;
};

/// One kind of terrain: the `model:` key of its files, a factory and a describer.
struct TerrainKind {
  std::string model;
  std::string what;  ///< one line for messages and listings
  /// `hooks`: called during a long preparation (PreparationHooks).
  std::function<std::unique_ptr<TerrainModel>(const YamlReader& file, const TerrainVehicle& vehicle,
                                              const PreparationHooks& hooks)>
      make;
  std::function<TerrainDescription(const YamlReader& file)> describe;
  /// Reads and checks every key of the file for `vehicle` as `make` does, building nothing
  /// (no soil is prepared): ConfigError for what `make` would refuse before it starts.
  std::function<void(const YamlReader& file, const TerrainVehicle& vehicle)> check;
  /// The model of a checkpoint, built without its preparation and read from it (empty: `make`,
  /// then TerrainModel::LoadState: a model with nothing to prepare).
  std::function<std::unique_ptr<TerrainModel>(const YamlReader& file, const TerrainVehicle& vehicle, StateReader& in)>
      restore;
};

/// The terrain kinds there are.
const std::vector<TerrainKind>& TerrainKinds();

/// Builds the terrain described by `terrain_file` (with `key=value` overrides, a scene's
/// terrain_overrides) for the wheels of `vehicle`. Throws ConfigError naming file and key of bad
/// input (an unknown `model:` lists the known ones). `hooks` are called while the terrain prepares
/// (a DEM soil: every step of its pour, lid and settling; PreparationHooks): once `stop` returns
/// true, the preparation stops within a step and Interrupted says where it was. `hooks.described` is
/// called exactly once: by a model that prepares for long as soon as it has read its file, else
/// by this function once the model is built.
std::unique_ptr<TerrainModel> LoadTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                                               const std::vector<std::string>& overrides = {},
                                               const PreparationHooks& hooks = {});
/// Reads and checks `terrain_file` (with overrides) for `vehicle` as LoadTerrainModel does, building
/// nothing: the check of `dm_run_scene --check`.
void CheckTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                       const std::vector<std::string>& overrides = {});
/// The same for a terrain file already read (the fuzz harness's text).
void CheckTerrainModel(const YamlReader& terrain_file, const TerrainVehicle& vehicle);
/// What `terrain_file` describes (model, cone index, time step, level), without building it (a
/// run learns it from its terrain once, through PreparationHooks::described; this is for a look
/// at a file, and the tests).
TerrainDescription DescribeTerrain(const std::string& terrain_file, const std::vector<std::string>& overrides = {});
/// The terrain of a checkpoint: the model `terrain_file` names, its state read from `in`.
std::unique_ptr<TerrainModel> RestoreTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                                                  const std::vector<std::string>& overrides, StateReader& in);

}  // namespace dem_mobility::core
