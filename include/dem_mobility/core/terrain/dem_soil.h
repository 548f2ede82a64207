// The DEM soil under tires: a soil bin (an open box, paper section 4.2) poured, consolidated by a
// lid at 33.3 kPa and released (SoilPreparation), and one wall per tire whose pose and velocity are
// set from the wheel's state. DemSoilBin is the part the single-wheel rig and the dem_soil terrain
// model share; DemSoilTerrain is the terrain model (terrain_model.h) over it.
//
// Frames: the bin is [0, length] x [-width / 2, width / 2] x [0, height] shifted by `origin` in the
// scene's frame (x forward, z up); a grade is the scene's rotated gravity, as on the road.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/cosim/exchange.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/scenes/calibration.h"
#include "dem_mobility/core/scenes/soil_prep.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;

/// One fidelity level of a soil bin: the particle size, the bin and the time step.
struct SoilBinLevel {
  std::string name;
  double particle_diameter = 0.06;  ///< [m] (overrides the soil file's)
  double length = 4.0, width = 1.0; ///< of the bin [m]
  double soil_depth = 0.4;          ///< consolidated depth the particle count is chosen for [m]
  double time_step = 8e-5;          ///< [s]
  double settle_time = 0.5;         ///< [s] after the pour
  double hold_time = 0.5;           ///< [s] at the lid pressure
};

/// The keys a soil bin is read from (a dem_soil terrain file, or a scene that holds a bin).
struct DemSoilParams {
  std::string file;
  SoilParams soil;                  ///< with the level's diameter, f and mu applied
  SoilBinLevel level;
  double cohesion_factor = 1.0;     ///< f
  double friction = 0.1;            ///< inter-particle mu
  double requested_ci = std::numeric_limits<double>::quiet_NaN();  ///< [psi] when f came from the table
  std::string calibration_file;
  std::shared_ptr<CiCalibration> calibration;  ///< the table used or naming f's CI (none: no table at this size)
  std::string no_table_reason;      ///< why no table names f's CI
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< the bin's (x = 0, y = 0, z = 0) in the scene
  double consolidation = 0.7;       ///< consolidated / poured depth, to choose the particle count
  double solid_fraction = 0.58;     ///< of the poured soil
  double tire_friction = 0.5;       ///< particle-tire mu (table 2)
  double tire_adhesion = 0.0;       ///< tire adhesion as a fraction of the particle's maximum
  double wall_margin = 0.0;         ///< tire candidate margin [m]; 0: the skin
  SoilPreparationParams prep;
  int threads = 1;
  unsigned seed = 1;
  double max_overlap = 0.4;         ///< overlap watchdog, fraction of d
  /// Reads the bin's keys from `y` (soil, fidelity, levels, cohesion_factor or cone_index with
  /// calibration, friction, bin, lid, tire_contact, threads, seed); the caller finishes `y`.
  /// ConfigError names the file and key.
  static DemSoilParams Read(const YamlReader& y);
  int ParticleCount() const;
  /// The cone index the soil stands for [psi]: the requested one, or the table's for f (NaN
  /// without a table).
  double ConeIndex() const;
  /// Writes the soil's figures (level, f, mu, CI, the calibration table used) into a result.
  void Describe(ResultFile* r) const;
};

/// The bin, its soil and the tire walls.
class DemSoilBin {
 public:
  /// Builds the bin, pours the particles and adds `wheels` tire walls parked above the bin.
  /// ConfigError when a tire is wider than the bin.
  DemSoilBin(const DemSoilParams& p, const TireGeometry& tire, int wheels);
  /// A copy (its own particles, walls and preparation): one prepared bin serves several runs.
  DemSoilBin(const DemSoilBin& o);
  DemSoilBin& operator=(const DemSoilBin&) = delete;
  /// One step of the preparation (pour, consolidate, retreat, release); SimulationError when it fails.
  void PrepareStep();
  bool prepared() const { return prep_->done(); }
  std::string phase() const { return SoilPreparation::PhaseName(prep_->phase()); }
  const SoilPreparation& preparation() const { return *prep_; }
  /// The consolidated surface (scene frame z) once prepared.
  double surface_height() const { return surface_; }

  /// Puts tire k where `s` says (the pose the next DEM step ends at) and moves its wrench point.
  void SetWheel(int k, const WheelState& s);
  /// The soil's wrench on tire k from the last force evaluation, about the centre it was set to.
  WheelWrench Wrench(int k) const;
  /// One DEM step.
  void Step() { dem_->Step(); }

  DemSystem& dem() { return *dem_; }
  const DemSystem& dem() const { return *dem_; }
  const DemSoilParams& params() const { return p_; }
  const TireGeometry& tire() const { return tire_; }
  int wheels() const { return static_cast<int>(tire_walls_.size()); }
  int tire_wall(int k) const { return tire_walls_[k]; }
  int lid_wall() const { return lid_; }
  double wall_height() const { return wall_height_; }
  /// The bin's walls (floor and sides).
  std::vector<int> container_walls() const { return container_; }

 private:
  DemSoilParams p_;
  TireGeometry tire_;
  std::unique_ptr<DemSystem> dem_;
  std::unique_ptr<SoilPreparation> prep_;
  std::vector<int> tire_walls_, container_;
  std::vector<Eigen::Vector3d> centres_;
  int lid_ = -1;
  double wall_height_ = 0.0, surface_ = 0.0;
};

/// The dem_soil terrain model: a DemSoilBin prepared when it is built, its tires following the
/// vehicle's wheels. Advance(dt) takes dt / time_step DEM steps (dt must be a whole multiple of
/// the soil's step), moving each tire on from its synchronized pose at its synchronized velocity;
/// the wrenches it returns are the means over those steps, so the impulse the wheels receive is
/// exactly minus the one the particles received.
class DemSoilTerrain final : public TerrainModel {
 public:
  DemSoilTerrain(const DemSoilParams& p, const TireGeometry& tire, int wheels);
  const TerrainDescription& description() const override { return description_; }
  void Synchronize(long step, double t, const std::vector<WheelState>& states) override;
  void GetWrenches(std::vector<WheelWrench>* wrenches) const override;
  void Advance(double dt) override;
  const TriMesh& Surface() const override { return surface_mesh_; }
  const DemSoilBin& bin() const { return *bin_; }

 private:
  std::unique_ptr<DemSoilBin> bin_;
  TerrainDescription description_;
  TriMesh surface_mesh_;
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
};

std::unique_ptr<TerrainModel> MakeDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle);
TerrainDescription DescribeDemSoilTerrain(const YamlReader& y);

}  // namespace dem_mobility::core
