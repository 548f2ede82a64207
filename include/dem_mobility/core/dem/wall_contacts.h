// Particle-wall contacts of the DEM: the walls, their world vertices, each slot's candidate
// triangles, one tangential history per slot and wall, and the walls' wrenches.
//
// Candidates: the triangles within d / 2 + margin of the particle at the wall build (the margin
// is the wall's own; the skin by default). A particle touches a
// triangle only within half a diameter of it, and a point of a rigid triangle moves no more than
// its vertices, so the candidates stay complete while a wall's largest vertex displacement plus the
// particles' largest displacement since the wall build stays below its margin. The candidates are
// rebuilt on their own when that is exceeded; a particle added since the last neighbour build tries
// every triangle.
//
// Binned walls (meshes of many triangles: a tire): the triangles are binned once in the wall's body
// frame (a rigid wall never changes shape), each cell listing every triangle that can be within
// reach of a point in it. A build looks up each particle's cell instead of scanning all triangles,
// so its cost scales with the particles near the wall; the candidates are the same, in the same
// order, as the scan's (DemSettings::wall_bins switches the bins off to compare).
//
// The deepest candidate of a binned wall: a particle near a tire has dozens of candidate triangles
// (the mesh is fine against the particles), and few of them can be nearer than the one found so
// far. A candidate whose distance has a lower bound at least that far (from its plane and its
// bounding circle in the body frame, with a margin far beyond round-off) is passed by without the
// closest point: the same triangle is chosen, with the same point, as by trying every candidate.
//
// The wrenches are summed in fixed chunks of slots, in slot order, and the chunks in order: the
// same sums for any thread count, without a force per particle and wall.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

/// A rigid triangle mesh the particles touch: a container side, a lid, a cone, a wheel. Its pose
/// and velocity are set from outside (static, prescribed motion, or driven by a multibody body);
/// the solver returns the particles' total force on it and the moment about `wrench_point`.
/// A particle touches a wall at one point (the deepest of its triangles), so a wall must be flat or
/// convex; a container is several walls.
struct DemWall {
  std::string name;
  TriMesh mesh;                                         ///< body coordinates
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   ///< body origin, world
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();   ///< of the body origin, world
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< world
  double friction = 0.5;          ///< particle-wall mu (0.5 to tire and cone, table 2)
  double adhesion_factor = 0.0;   ///< wall adhesion as a fraction of the particle's maximum adhesion
  Eigen::Vector3d wrench_point = Eigen::Vector3d::Zero();  ///< world point the moment is about
  /// A fast tool (a wheel: much faster than the soil): its motion rebuilds only the wall candidates
  /// (WallContacts::NeedsBuild). A slow one (container, lid, cone) moving half the skin rebuilds
  /// the particles' neighbour lists too, as a particle moving that far does.
  bool fast = false;
  /// How far the wall and the particles may move between candidate builds [m]; <= 0: the default,
  /// the skin (d * skin: a static wall then needs no build of its own, the particles moving at most
  /// the skin between builds). A smaller margin means fewer candidates per particle and more
  /// builds. (A slow wall's default was cutoff - d / 2 until 2026-12-05: six times the skin, the
  /// particles of two layers along a box's walls its candidates, for the same forces.)
  double margin = 0.0;
  // results of the last force evaluation
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< on the wall, world
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< on the wall about wrench_point, world
  double normal_force = 0.0;  ///< sum of the contacts' normal forces (> 0 pushing)
  int contacts = 0;
};

/// A flat rectangular wall: corner `o`, edges `e1` and `e2` (two triangles).
DemWall MakeQuadWall(const std::string& name, const Eigen::Vector3d& o, const Eigen::Vector3d& e1,
                     const Eigen::Vector3d& e2);

class WallContacts {
 public:
  /// `cutoff`: the neighbour lists' cutoff; `diameter`: the particles' contact diameter; `bins`:
  /// bin the triangles of large walls (false: every build scans every triangle).
  WallContacts(double cutoff, double diameter, bool bins = true)
      : cutoff_(cutoff), diameter_(diameter), use_bins_(bins) {}
  /// Walls with at least this many triangles are binned.
  static constexpr int kBinMinFaces = 64;

  /// Adds a wall (before the first build, `slots` slots so far); returns its index.
  int Add(DemWall wall, const SoilParams& soil, int slots);
  int size() const { return static_cast<int>(walls_.size()); }
  DemWall& wall(int w) { return walls_[w]; }
  const DemWall& wall(int w) const { return walls_[w]; }

  /// A slot appended to the store (`built`: after the first build, so it gets an empty candidate list).
  void AppendSlot(bool built);
  /// Forgets slot s's wall contacts (its particle was added or removed).
  void ClearSlot(int s);
  /// Follows the store's permutation (new slot s holds old slot order[s]).
  void PermuteSlots(const std::vector<int>& order);
  /// The slow walls' world vertices from their present poses (`all`: every wall's, as a build
  /// needs; a fast wall's are taken where a contact needs them), then each wall's displacement
  /// from the wall build (Displacements).
  void UpdateVertices(bool all = false);
  /// Whether the candidates may miss a contact once the particles have moved up to
  /// `particle_displacement` from x_built.
  bool NeedsBuild(double particle_displacement) const;
  /// Each live slot's candidate triangles at the present positions; `particle_displacement`: the
  /// largest distance of a particle from its x_built now (0 right after a neighbour build).
  void Build(const ParticleStore& ps, int threads, double particle_displacement);
  /// Adds the wall contacts' forces (and maxima) to the particles' sums (ps->sums, packed by the
  /// force evaluation); sets the walls' wrenches. Returns the walls' power on the particles.
  double Compute(ParticleStore* ps, double dt, int threads);

  /// The largest distance of a vertex of the fast (or the slow) walls from where it was at the
  /// wall build (for the fast ones, its bound from their poses: FastDisplacement).
  double MaxWallDisplacement(bool fast) const;
  /// The largest distance of a vertex of wall w from where it was at the wall build, as of the last
  /// UpdateVertices (a fast wall's: its bound from its pose, never below it).
  double WallDisplacement(int w) const;
  double margin(int w) const { return margin_[w]; }
  bool binned(int w) const { return !bins_[w].start.empty(); }
  long builds() const { return builds_; }
  /// Candidate triangles over all slots at the last build (a measure of the per-step cost).
  long candidates() const { return static_cast<long>(tri_of_slot_.size()); }
  size_t MemoryBytes() const;
  /// Its state in a checkpoint (common/state_archive.h): the walls' poses, velocities and wrenches,
  /// the candidates and their histories. The walls themselves (meshes, bins, laws) are the built
  /// scene's: their number and sizes are checked.
  template <class Ar>
  void Io(Ar& ar);
  /// Whether the per-slot arrays hold `slots` slots (a checkpoint's walls against its particles).
  bool Holds(int slots) const {
    return hist_.size() == static_cast<size_t>(slots) * walls_.size() && touching_.size() == hist_.size() &&
           (tri_start_.empty() || tri_start_.size() == static_cast<size_t>(slots) + 1);
  }

 private:
  struct WallTri {
    using StateBulk = void;
    int wall, face;
  };
  /// A wall's triangles binned in its body frame: cell (ix, iy, iz) lists, in increasing order, the
  /// faces whose centroid lies within (largest centroid-vertex distance + reach) of the cell.
  struct Bins {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero();
    double cell = 1.0;
    int nx = 0, ny = 0, nz = 0;
    std::vector<int> start, faces;  ///< CSR per cell
    int Cell(const Eigen::Vector3d& body) const;
  };
  /// A triangle in its wall's body frame: its centroid, its unit normal (zero if it has no area)
  /// and the largest distance of a vertex from the centroid (grown a little). The distance of a point
  /// from the triangle is at least sqrt(h^2 + max(0, l - rho)^2), h and l the point's distances
  /// from its plane and, in the plane, from its centroid.
  struct TriBound {
    using StateBulk = void;
    Eigen::Vector3d centroid, normal;
    double rho;
  };
  struct WallSum {
    using StateBulk = void;
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    double power = 0.0, normal = 0.0;
    int contacts = 0;
  };
  /// displacement_: a slow wall's from vertices_ and built_vertices_, a fast wall's from its pose.
  void Displacements();
  /// A bound on the distance of any vertex of fast wall w from where it was at the build, from the
  /// rigid motion since: |p - p_b| + ||R - R_b||_F max|v| (v in the body frame), plus the round-off.
  double FastDisplacement(int w) const;
  void ClearHistory(size_t hw) {
    if (touching_[hw]) {
      hist_[hw] = TangentialHistory();
      touching_[hw] = 0;
    }
  }
  void ComputeSlot(ParticleStore* ps, int i, double dt, WallSum* sum);
  void MakeBins(int w);
  /// Appends slot i's candidates to `out`.
  void SlotCandidates(const Eigen::Vector3d& x, std::vector<int>* out) const;
  bool Near(const Eigen::Vector3d& x, int t) const;
  double SumWrenches(int chunks);

  double cutoff_, diameter_;
  bool use_bins_;
  long builds_ = 0;
  std::vector<double> margin_, reach_;  ///< per wall: its margin, and d / 2 + margin
  std::vector<Bins> bins_;
  std::vector<int> tri_begin_;          ///< per wall: its first index in tris_
  std::vector<Eigen::Vector3d> tri_lo_, tri_hi_;  ///< per triangle: its world box at the build, grown by the reach
  std::vector<Eigen::Vector3d> wall_lo_, wall_hi_;  ///< per wall: the box of its triangles' boxes
  std::vector<std::vector<int>> chunk_tris_;      ///< per chunk of slots at a build: the candidates
  std::vector<int> count_;                        ///< per slot at a build: its number of candidates
  std::vector<DemWall> walls_;
  std::vector<SoilContactLaw> law_;  ///< the soil law with each wall's friction
  /// world: now (a fast wall's as of its build) and, for a slow wall, at the build
  std::vector<std::vector<Eigen::Vector3d>> vertices_, built_vertices_;
  std::vector<double> displacement_;  ///< per wall: its largest vertex distance between the two
  std::vector<double> radius_;        ///< per wall: its largest vertex distance from the body origin
  std::vector<Eigen::Vector3d> built_position_;  ///< per wall: its pose at the build
  std::vector<Eigen::Matrix3d> built_rotation_;
  double built_particle_displacement_ = 0.0;  ///< the particles' largest distance from x_built at the build
  std::vector<WallTri> tris_;
  std::vector<TriBound> tri_bound_;  ///< per triangle (body frame; used on binned walls)
  std::vector<int> tri_start_, tri_of_slot_;  ///< CSR: candidate triangles per slot, in wall order
  std::vector<TangentialHistory> hist_;       ///< per slot and wall
  std::vector<unsigned char> touching_;       ///< per slot and wall
  // PermuteSlots' scratch (kept from build to build): the slots touching a wall, their rows of
  // touching_ and the histories of the walls they touch, and each old slot's new one
  std::vector<int> moved_slot_, new_slot_;
  std::vector<TangentialHistory> moved_hist_;
  std::vector<unsigned char> moved_touching_;
  std::vector<WallSum> chunk_;                ///< per chunk of slots and wall
};

}  // namespace dem_mobility::core
