// The moving soil patch (paper section 4.2, fig. 18) over a prepared DemSoilBin: a bounding
// sphere, an emitter ahead of the vehicle, and a leveling cylinder and plate at the initial soil
// height. A particle that leaves the sphere's rear half is removed and re-emitted at once, so the
// particle count never changes (the soil the emitter lays ahead drifts a little past the sphere's
// front: held to the whole sphere it would leave again at once). Once the centroid of the wheel centres (the terrain sees the wheels, not
// the chassis) reaches the sphere's initial centre, the sphere, the emitter and the leveling tools
// follow it along x (the grade is the scene's rotated gravity, so x is along the slope). The floor
// and side walls reach over the whole travel and their material does not move, which to the soil
// is the same as a box that follows; only the bin's end walls are left behind.
//
// The emitter lays the soil down again as the prepared bed was: it holds a template, the
// particles of a slice of the bed (positions and plastic deformation, so the consolidation-
// dependent adhesion comes back with them) just behind its front, taken when the patch starts
// to follow (the released bed relaxes for a while; the checks compare with the bed as it is
// then, ahead of the front wheels), and fills copies of it
// ahead of the bed's front one layer (one particle diameter along x) at a time, each re-emitted
// particle at a random free site among the lowest of the layer being filled (the layer is laid
// from the bottom up; a seeded generator: runs repeat bit for bit). A random point of a plane emitter would drop loose soil that the wheels then meet
// less dense than the consolidated bed; the template gives the bed's density and surface by
// construction, and the patch checks both ahead of the front wheels against the initial bed.
// Template sites that would overlap soil already there (at the seams between copies, or a
// particle that fell or was thrown there) are skipped; the copies follow each other at the shift
// (about the slice's length) at which the fewest sites clash per length laid. A particle that strays into the emitter's zone (thrown ahead, or pushed by the plate)
// is re-emitted like one that left the sphere. The particles laid are held in place
// (DemSystem::set_held) until the layer after theirs is complete: a laid face left free would
// relax into the next layer's sites before they are filled, and the soil would come out light.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dem_mobility/core/soil/dem_soil_bin.h"

namespace dem_mobility::core {

class StateReader;

/// The soil in a window: bulk density of its lower three quarters and the mean top of its
/// columns.
struct PatchSoilMeasure {
  using StateBulk = void;
  double density = std::numeric_limits<double>::quiet_NaN();  ///< [kg/m^3]
  double surface = std::numeric_limits<double>::quiet_NaN();  ///< [m] (scene z)
  int particles = 0;
  double reemitted_fraction = 0.0;  ///< of the particles counted: re-emitted ones
};

/// One check of the soil ahead of the front wheels (every check period once the patch follows).
struct PatchCheck {
  using StateBulk = void;
  double t = 0.0;                   ///< [s] the soil's time
  double front_x = 0.0;             ///< [m] the front wheels' centres (x)
  double density_ratio = 0.0;       ///< the window's bulk density over the initial bed's
  double surface_offset = 0.0;      ///< [m] its mean surface less the initial bed's
  double reemitted_fraction = 0.0;  ///< of its particles: re-emitted ones (a check counts from 0.9)
  int particles = 0;
};

/// What the patch has done so far.
struct PatchStats {
  long reemitted = 0;             ///< particles re-emitted (left the sphere or strayed)
  long strays = 0;                ///< of those, strays from the emitter's zone
  long skipped_sites = 0;         ///< template sites skipped: soil already there
  int copies = 0;                 ///< template copies begun
  /// [m] how far the bed's face (its columns' median foremost particle) stood behind where the
  /// front wall held it (half a diameter inside it) when the first copy was laid against it: the
  /// bed's slump down a grade (NaN until the first copy)
  double face_setback = std::numeric_limits<double>::quiet_NaN();
  bool following = false;
  PatchSoilMeasure initial;       ///< the bed ahead of the front wheels when the patch starts to follow
  // the checks with at least 90 % re-emitted soil in the window
  int checks = 0;
  double density_ratio_mean = std::numeric_limits<double>::quiet_NaN();  ///< re-emitted / initial
  double density_ratio_min = std::numeric_limits<double>::quiet_NaN(), density_ratio_max = std::numeric_limits<double>::quiet_NaN();
  double surface_offset_mean = std::numeric_limits<double>::quiet_NaN(); ///< [m] re-emitted - initial
  double surface_offset_max = std::numeric_limits<double>::quiet_NaN();  ///< largest |offset| [m]
  /// [m/s] the largest mean speed down the grade (-x) of the bed's bottom layer (a diameter deep, in
  /// the middle half of the box) over the check periods once the patch follows: the bed creeping
  /// or sliding on the box's floor (reported, not acted on: docs/vehicle-on-soil.md)
  double bed_slide_speed_max = 0.0;
  std::vector<PatchCheck> log;    ///< every check made, those under 90 % re-emitted soil too
  template <class Ar>
  void Io(Ar& ar) {
    ar(reemitted, strays, skipped_sites, copies, face_setback, following, initial, checks, density_ratio_mean,
       density_ratio_min, density_ratio_max, surface_offset_mean, surface_offset_max, bed_slide_speed_max, log);
  }
};

/// The patch's checks as CSV (t, front_x, density_ratio, surface_offset, reemitted_fraction,
/// particles): what the soil ahead of the wheels was like along the run. ConfigError naming the
/// path when it cannot be written.
void WritePatchChecks(const PatchStats& s, const std::string& path);

class SoilPatch {
 public:
  /// Over a prepared bin whose patch is enabled: takes the template and sets the sphere.
  SoilPatch(DemSoilBin* bin, const SoilPatchParams& p, unsigned seed);
  /// A copy bound to `bin` (a copy of the original's bin).
  SoilPatch(const SoilPatch& o, DemSoilBin* bin);
  /// The patch of a checkpoint over `bin` (restored already): every figure read from `in`, none
  /// measured on the bin (whose bed may have travelled far from where it was prepared).
  SoilPatch(DemSoilBin* bin, const SoilPatchParams& p, StateReader& in);
  /// Before each DEM step, with the wheel centres at the end of that step: follows, moves the
  /// tools, re-emits what left, and checks the soil ahead every check period. SimulationError when
  /// the patch runs off the end of its floor.
  void BeforeStep(const std::vector<Eigen::Vector3d>& wheel_centres);

  const PatchStats& stats() const { return stats_; }
  Eigen::Vector3d sphere_centre() const { return centre_; }
  double sphere_radius() const { return radius_; }
  /// The box that follows (for display): its rear and front x, the floor's z, width and height.
  double box_rear() const { return centre_.x() - 0.5 * bed_length_; }
  double box_front() const { return centre_.x() + 0.5 * bed_length_; }
  double floor_z() const { return floor_z_; }
  double initial_surface() const { return surface0_; }
  /// The emitter's zone: the layer being filled spans [emitter_from, emitter_to] along x.
  double emitter_from() const;
  double emitter_to() const;
  /// The soil in [x0, x1) (y within the soil's side walls less 1.5 d: the whole width, or the
  /// two strips under the wheel tracks).
  PatchSoilMeasure Measure(double x0, double x1) const;
  int initial_particles() const { return n0_; }
  /// Its state in a checkpoint (common/state_archive.h): the sphere, the template, the emitter's
  /// layer, its random generator and the checks so far.
  template <class Ar>
  void Io(Ar& ar);

 private:
  struct Site {
    using StateBulk = void;
    Eigen::Vector3d x;  ///< relative to the copy's origin (x) and the scene (y, z)
    double plastic;
  };
  /// The template and the emitter's layers from the bed as it is now.
  void CaptureTemplate();
  void StartCopy();
  void NextLayer();
  /// The particles near the layer being filled.
  void GatherZone();
  bool Blocked(const Eigen::Vector3d& x) const;
  void Emit();
  void Check(double front_wheels_x);
  void PlaceTools(double velocity);
  /// The plate's height once lowered: the initial surface plus the leveling clearance.
  double ToolWorkingHeight() const;
  /// Whether y (from the bin's centre line) lies in the soil's bands, 1.5 d inside their walls.
  bool InSoil(double y) const;

  DemSoilBin* bin_;
  SoilPatchParams p_;
  std::mt19937_64 rng_;
  double d_ = 0.0, bed_length_ = 0.0, width_ = 0.0, floor_z_ = 0.0, surface0_ = 0.0, depth0_ = 0.0;
  double front_x0_ = 0.0, template_length_ = 0.0, min_site_x_ = 0.0;
  std::vector<std::pair<double, double>> walls_y_;  ///< the soil's [lo, hi] in y between its side walls
  std::vector<std::pair<double, double>> bands_;  ///< the same, 1.5 d inside its walls
  double band_width_ = 0.0;          ///< their sum
  double period_ = 0.0;              ///< shift from one copy to the next
  int seam_clash_ = 0;               ///< sites of a copy that clash with the copy before at that shift
  Eigen::Vector3d centre0_ = Eigen::Vector3d::Zero(), centre_ = Eigen::Vector3d::Zero();
  double radius_ = 0.0;
  int n0_ = 0;
  std::vector<Site> sites_;          ///< sorted by x
  std::vector<int> layer_begin_;     ///< sites_ index of each layer's first site (+ end)
  double copy_origin_ = 0.0;         ///< x of the copy being filled
  int layer_ = -1;                   ///< the layer being filled
  std::vector<int> free_;            ///< its free sites, lowest first
  std::vector<Eigen::Vector3d> zone_;  ///< particles near the layer being filled
  std::vector<int> leaving_;         ///< this step's particles to re-emit (kept: no allocation per step)
  int prev_layer_first_id_ = 0, layer_first_id_ = 0;
  bool started_ = false;
  double tool_offset_ = 0.0;         ///< leveling cylinder x - sphere centre x
  double tool_z_ = 0.0;              ///< the plate's height now (lowered to its working height)
  double front_offset_ = 0.0;        ///< front wheels' x - wheel centroid x (at the start)
  long steps_ = 0, check_every_ = 1;
  double bed_vx_sum_ = 0.0;          ///< over this check period: the lower half's velocity along x
  long bed_vx_count_ = 0;
  double ratio_sum_ = 0.0, offset_sum_ = 0.0;
  PatchStats stats_;
};

}  // namespace dem_mobility::core
