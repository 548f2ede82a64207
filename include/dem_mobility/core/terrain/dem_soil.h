// The DEM soil under tires: a soil bin (an open box, paper section 4.2) poured, consolidated by a
// lid at 33.3 kPa and released (SoilPreparation), and one wall per tire whose pose and velocity are
// set from the wheel's state. DemSoilBin is the part the single-wheel rig and the dem_soil terrain
// model share; DemSoilTerrain is the terrain model (terrain_model.h) over it.
//
// Frames: the bin is [0, length] x [-width / 2, width / 2] x [0, height] shifted by `origin` in the
// scene's frame (x forward, z up); a grade is the scene's rotated gravity, as on the road.
#pragma once

#include "dem_mobility/core/common/energy.h"

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
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
class StateReader;
class StateWriter;

/// One fidelity level of a soil bin: the particle size, the bin and the time step.
struct SoilBinLevel {
  std::string name;
  double particle_diameter = 0.06;  ///< [m] (overrides the soil file's)
  double length = 4.0, width = 1.0; ///< of the bin [m]
  double soil_depth = 0.4;          ///< consolidated depth the particle count is chosen for [m]
  double time_step = 8e-5;          ///< [s]
  double settle_time = 0.5;         ///< [s] after the pour
  double hold_time = 0.5;           ///< [s] at the lid pressure
  /// [m/s] the level's speed-made-good error against the finest level run (the fidelity study,
  /// docs/vehicle-on-soil.md); NaN: not measured
  double speed_error = std::numeric_limits<double>::quiet_NaN();
  std::string speed_error_note;     ///< where that figure comes from
};

/// The moving soil patch (paper section 4.2, fig. 18): particles that leave a bounding sphere are
/// re-emitted at once ahead of the vehicle; once the vehicle's wheels reach the sphere's initial
/// centre, the sphere, the emitter and the leveling cylinder and plate follow them along the
/// grade. Without the `patch:` map the bin is fixed.
struct SoilPatchParams {
  bool enabled = false;
  double travel = 800.0;          ///< [m] the floor and side walls reach this far beyond the bin's front
  double sphere_margin = 0.1;     ///< [m] of the sphere beyond the bed's half-diagonal
  double template_length = 2.0;   ///< [m] the slice of the prepared bed the emitter lays down again
  double seam_clearance = 0.8;    ///< [d] a template site closer than this to soil already there is skipped
  double leveling_ahead = 2.1;    ///< [m] cylinder axis ahead of the front wheels' centres (at the start)
  double leveling_radius = 0.1;   ///< [m]
  double plate_length = 0.6;      ///< [m] plate behind the cylinder
  double leveling_clearance = 0.25;  ///< [d] of the plate's underside above the initial surface
  double check_from = 0.6, check_to = 1.4;  ///< [m] ahead of the front wheels' centres: the re-emitted soil checked there
  double check_period = 0.05;     ///< [s] between checks
  /// Reads the `patch` map; ConfigError names the file and key.
  static SoilPatchParams Read(const YamlReader& y);
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
  SoilPatchParams patch;
  int threads = 1;
  unsigned seed = 1;
  /// `time_step_guard: false`: the level's time step runs even above the soil's critical step
  /// (stability studies only: docs/stability.md)
  bool time_step_guard = true;
  double max_overlap = 0.4;         ///< overlap watchdog, fraction of d
  /// [m] `track_strip_width`: > 0, soil only in two strips this wide centred under the wheel tracks
  /// (at y = +-strip_offset from the bin's centre line), each between walls of its own, with a
  /// rigid floor 1.5 d below the bed's nominal surface between and beside them (a scene that needs no soil
  /// between the tracks); 0, soil over the bin's whole width
  double strip_width = 0.0;
  double strip_offset = 0.0;        ///< [m] each strip's centre line from the bin's: half the vehicle's track
  /// The soil's extent across the bin: [lo, hi] in y from its centre line, one band (the whole
  /// width) or two strips.
  std::vector<std::pair<double, double>> SoilBands() const;
  /// The soil's width across y: the bands' sum.
  double SoilWidth() const;
  /// Reads the bin's keys from `y` (soil, fidelity, levels, cohesion_factor or cone_index with
  /// calibration, friction, bin, lid, tire_contact, threads, seed, track_strip_width); the caller
  /// finishes `y`.
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
  /// One DEM step (and a sample of the soil's energy ledger when it is followed).
  void Step() {
    dem_->Step();
    if (watch_every_ > 0 && dem_->step_count() % watch_every_ == 0) watch_.Sample(dem_->Energy(), dem_->time());
  }
  /// Follows the soil's energy ledger from now on (a run's start, after the preparation): a sample
  /// now and every `period` seconds of soil time (LedgerWatch).
  void WatchEnergy(double period);
  const LedgerWatch& energy_watch() const { return watch_; }
  /// The soil's critical step (soil_critical_time_step, _detail) and the watch in a result:
  /// soil_energy_dissipated, _least, _largest_fall, _scale, _samples, and the wall work and
  /// exchanged energy since the watch began.
  void DescribeEnergy(ResultFile* r) const;

  DemSystem& dem() { return *dem_; }
  const DemSystem& dem() const { return *dem_; }
  const DemSoilParams& params() const { return p_; }
  const TireGeometry& tire() const { return tire_; }
  int wheels() const { return static_cast<int>(tire_walls_.size()); }
  int tire_wall(int k) const { return tire_walls_[k]; }
  int lid_wall() const { return lid_; }
  double wall_height() const { return wall_height_; }
  /// The bin's walls (floor, rear, front and sides, in this order).
  std::vector<int> container_walls() const { return container_; }
  /// The moving patch's leveling cylinder and plate (-1 without a patch).
  int leveling_cylinder() const { return cylinder_; }
  int leveling_plate() const { return plate_; }
  /// The floor's z in the scene (after any ShiftZ).
  double floor_z() const { return p_.origin.z() + shift_; }
  /// Moves the soil and every wall by dz along z (the prepared surface to z = 0 under a vehicle).
  void ShiftZ(double dz);
  /// Its state in a checkpoint (common/state_archive.h): the soil, the preparation, the tires'
  /// centres and the energy watch.
  template <class Ar>
  void Io(Ar& ar);

 private:
  DemSoilParams p_;
  TireGeometry tire_;
  std::unique_ptr<DemSystem> dem_;
  std::unique_ptr<SoilPreparation> prep_;
  std::vector<int> tire_walls_, container_;
  std::vector<Eigen::Vector3d> centres_;
  int lid_ = -1, cylinder_ = -1, plate_ = -1;
  double wall_height_ = 0.0, surface_ = 0.0, shift_ = 0.0;
  LedgerWatch watch_;
  long watch_every_ = 0;
  EnergyReport watch_start_;
  double watch_plastic_ = 0.0;
};

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

/// The dem_soil terrain of a terrain file. With the environment variable DM_SOIL_CACHE naming a
/// folder, a soil prepared before by this build from the same file (overrides applied), soil file,
/// calibration tables and tire is read from it instead of being prepared again (bit for bit the
/// same state: the preparation is deterministic), and a soil prepared here is written there; the
/// result says `soil_prepared_from`. A cached file that does not read is prepared again (a warning).
std::unique_ptr<TerrainModel> MakeDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle,
                                                 const PreparationHooks& hooks = {});
TerrainDescription DescribeDemSoilTerrain(const YamlReader& y);
/// The dem_soil terrain of a checkpoint (DemSoilTerrain's restoring constructor).
std::unique_ptr<TerrainModel> RestoreDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle, StateReader& in);
/// Reads and checks the bin's keys for `vehicle` as MakeDemSoilTerrain does, preparing no soil.
void CheckDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle);

}  // namespace dem_mobility::core
