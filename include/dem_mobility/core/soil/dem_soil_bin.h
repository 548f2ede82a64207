// The DEM soil under tires: a soil bin (an open box, paper section 4.2) poured, consolidated by a
// lid at 33.3 kPa and released (SoilPreparation), and one wall per tire whose pose and velocity are
// set from the wheel's state. The single-wheel rig and the dem_soil terrain model
// (terrain/dem_soil.h) share it.
//
// Frames: the bin is [0, length] x [-width / 2, width / 2] x [0, height] shifted by `origin` in the
// scene's frame (x forward, z up); a grade is the scene's rotated gravity, as on the road.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/soil/dem_soil_params.h"
#include "dem_mobility/core/soil/soil_prep.h"

namespace dem_mobility::core {

class ResultFile;

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

}  // namespace dem_mobility::core
