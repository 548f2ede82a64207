// The dem_soil terrain model: a DEM soil bin (soil/dem_soil_bin.h) behind the co-simulation
// terrain's lifecycle (terrain_model.h), with a moving soil patch when the file asks for one.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/soil/dem_soil_bin.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;
class StateReader;
class StateWriter;

class SoilPatch;

/// The dem_soil terrain model: a DemSoilBin prepared when it is built (its surface then moved to
/// z = 0, where the vehicle starts with its tires touching), its tires following the vehicle's
/// wheels; with a `patch:` map, a moving soil patch (soil_patch.h). Advance(dt) takes dt / time_step DEM steps (dt must be a whole multiple of
/// the soil's step), moving each tire on from its synchronized pose at its synchronized velocity;
/// the wrenches it returns are the means over those steps, so the impulse the wheels receive is
/// exactly minus the one the particles received.
class DemSoilTerrain final : public TerrainModel {
 public:
  /// Prepares the soil (pour, lid, settling); `hooks.stop` (may be empty) is called every step of
  /// it: once it returns true, Interrupted names the phase and the simulated time reached;
  /// `hooks.progress` hears where it is (PreparationHooks).
  DemSoilTerrain(const DemSoilParams& p, const TireGeometry& tire, int wheels, const PreparationHooks& hooks = {});
  /// The terrain of a checkpoint (common/state_archive.h): the bin built for `p` as above but not
  /// prepared, then its soil, patch and exchange state read from `in` (ConfigError naming the
  /// file when the checkpoint is not of this soil).
  DemSoilTerrain(const DemSoilParams& p, const TireGeometry& tire, int wheels, StateReader& in);
  /// A copy (its own particles, walls and patch): one prepared soil serves several runs.
  DemSoilTerrain(const DemSoilTerrain& o);
  DemSoilTerrain& operator=(const DemSoilTerrain&) = delete;
  ~DemSoilTerrain() override;
  /// OpenMP threads of the soil from the next step on (the results do not depend on it).
  void set_threads(int threads) { bin_->dem().set_threads(threads); }
  const TerrainDescription& description() const override { return description_; }
  void Synchronize(long step, double t, const std::vector<WheelState>& states) override;
  void GetWrenches(std::vector<WheelWrench>* wrenches) const override;
  void Advance(double dt) override;
  const TriMesh& Surface() const override { return surface_mesh_; }
  TerrainDisplay Display() const override;
  void Describe(ResultFile* r) const override;
  /// The grade's gravity on every particle (prepared under gravity along -z, the bed's normal: one
  /// prepared bed serves every grade; it settles under the rotated gravity with the vehicle).
  void SetGravity(const Eigen::Vector3d& g) override;
  void SaveState(StateWriter& out) const override;
  void LoadState(StateReader& in) override;
  const DemSoilBin& bin() const { return *bin_; }
  DemSoilBin& mutable_bin() { return *bin_; }
  /// The moving patch (nullptr without one).
  const SoilPatch* patch() const { return patch_.get(); }
  /// Wall seconds spent preparing the soil (or reading it prepared) and advancing it.
  double prepare_wall_time() const { return prepare_wall_; }
  /// The prepared soil it was read from (PreparedSoilCache), "" when it was prepared here.
  const std::string& prepared_from() const { return prepared_from_; }
  /// Says that the soil was read prepared from `path` in `seconds` (not prepared here).
  void SetPreparedFrom(const std::string& path, double seconds) {
    prepared_from_ = path;
    prepare_wall_ = seconds;
  }
  double advance_wall_time() const { return advance_wall_; }

 private:
  template <class Ar>
  void Io(Ar& ar);
  /// The display surface over the bin's consolidated top (with a patch, over the whole travel).
  void MakeSurfaceMesh();

  std::unique_ptr<DemSoilBin> bin_;
  std::unique_ptr<SoilPatch> patch_;
  double prepare_wall_ = 0.0, advance_wall_ = 0.0;
  std::string prepared_from_;
  double start_gap_ = 0.0;  ///< [m] the start plane z = 0 above the bed's surface (the highest particle's top)
  TerrainDescription description_;
  TriMesh surface_mesh_;
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
};

/// The dem_soil terrain of a terrain file. With `hooks.prepared_soil_cache` naming a folder, a soil
/// prepared before by this build from the same file (overrides applied), soil file, calibration
/// tables and tire is read from it instead of being prepared again (PreparedSoilCache), and a soil
/// prepared here is written there; the result says `soil_prepared_from`.
std::unique_ptr<TerrainModel> MakeDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle,
                                                 const PreparationHooks& hooks = {});
TerrainDescription DescribeDemSoilTerrain(const YamlReader& y);
/// The dem_soil terrain of a checkpoint (DemSoilTerrain's restoring constructor).
std::unique_ptr<TerrainModel> RestoreDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle, StateReader& in);
/// Reads and checks the bin's keys for `vehicle` as MakeDemSoilTerrain does, preparing no soil.
void CheckDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle);

}  // namespace dem_mobility::core
