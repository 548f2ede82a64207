// The keys a DEM soil bin is read from (a dem_soil terrain file, or a scene that holds a bin: the
// single-wheel rig): the fidelity level (particle size, bin, time step), the soil's strength, the
// lid, the tire contact, the moving patch and the strips under the wheel tracks.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/soil/soil_strength.h"

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
  double friction = 0.1;            ///< inter-particle mu
  /// f, and the table it came from or that names its CI (none: no table at this size)
  SoilStrength strength;
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
  /// Writes the soil's figures (level, f, mu, CI, the calibration table used) into a result.
  void Describe(ResultFile* r) const;
};

}  // namespace dem_mobility::core
