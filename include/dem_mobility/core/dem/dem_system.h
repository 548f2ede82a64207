// The explicit DEM solver for the cohesive soil (paper section 2.3): point particles (3
// translational DOF) with a contact diameter, the soil law of soil_law.h between every pair,
// velocity Verlet (the explicit member of the multibody core's trapezoidal family), a Cartesian
// cell grid with a Verlet skin, and OpenMP.
//
// Determinism without atomics or per-thread force copies: each pair is listed once (half list) and
// evaluated once, adding its force to both particles. The domain is cut into slabs at least one
// neighbour cutoff thick along its longest axis, and a pair belongs to the particle in the lower
// slab (or, in the same slab, the lower index); so a slab's pairs write only to its own and the next
// slab's particles. The even slabs run in parallel, then the odd ones; each slab is swept by one
// thread in ascending particle order. The slabs depend on the particles only, not on the thread
// count, so every particle's force is summed in the same order for any number of threads: the
// result is bit-for-bit the same.
//
// Particles can be added and removed between steps without a full rebuild: a new particle finds its
// neighbours in the last build's cell grid (against the positions at that build, which keeps the
// Verlet-skin guarantee) and its pairs go into their owners' lists, which have a little spare room; a
// removed particle is taken out of the lists and its slot is reused by the next one added. Indices
// of the other particles never change.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility {

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
  // results of the last force evaluation
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< on the wall, world
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< on the wall about wrench_point, world
  int contacts = 0;
};

/// A flat rectangular wall: corner `o`, edges `e1` and `e2` (two triangles).
DemWall MakeQuadWall(const std::string& name, const Eigen::Vector3d& o, const Eigen::Vector3d& e1,
                     const Eigen::Vector3d& e2);

struct DemSettings {
  double skin = 0.1;            ///< Verlet skin as a fraction of the diameter
  int threads = 1;              ///< OpenMP threads
  double max_overlap = 0.25;    ///< watchdog: largest overlap / diameter before the run stops (the
                                ///< soil sits at d0 = 5 % and compacts plastically by up to ~8 % more)
  int max_coordination = 12;    ///< contacts per particle assumed by the time-step guard
  int list_slack = 2;           ///< spare neighbour slots per particle for particles added later
};

class DemSystem {
 public:
  DemSystem(const SoilParams& soil, const DemSettings& settings);

  /// Adds a particle (before or between steps); returns its ID (0, 1, 2, ... in the order added;
  /// an ID is never reused). Between steps the neighbour lists are extended in place (no full
  /// rebuild, unless a neighbour's list has no spare room left).
  int AddParticle(const Eigen::Vector3d& x, const Eigen::Vector3d& v = Eigen::Vector3d::Zero());
  /// Removes a particle (between steps): its contacts vanish; its storage is reused.
  void RemoveParticle(int id);
  bool alive(int id) const { return slot_of_id_[id] >= 0; }
  int num_alive() const { return static_cast<int>(slot_of_id_.size()) - removed_; }
  /// Gravity in any direction (a grade is a rotated gravity vector). Changing it during a run
  /// enters the energy ledger as exchanged energy.
  void set_gravity(const Eigen::Vector3d& g);
  /// Adds a wall (before Finalize); returns its index. A moving wall gets its pose and velocity
  /// set through mutable_wall() before each Step (prescribed motion, or a multibody body's state).
  int AddWall(DemWall wall);
  DemWall& mutable_wall(int w) { return walls_[w]; }
  const DemWall& wall(int w) const { return walls_[w]; }
  int num_walls() const { return static_cast<int>(walls_.size()); }

  TimeStepLimit CriticalTimeStep() const;
  /// Refuses (ConfigError naming the limit) a step above the critical one; computes the forces.
  void Finalize(double dt);
  /// One step. Throws SimulationError naming the step, the particle (ID) and the quantity when a
  /// watchdog trips (a non-finite state or force, an overlap beyond max_overlap, a particle moving
  /// more than half the skin in one step); the state at the failure stays readable (for saving).
  void Step();

  /// IDs handed out so far (removed particles included).
  int size() const { return static_cast<int>(slot_of_id_.size()); }
  long step_count() const { return step_; }
  double time() const { return time_; }
  double dt() const { return dt_; }
  // one particle by ID (a removed one: its last state until its storage is reused, then NaN)
  Eigen::Vector3d position(int id) const { return Get(x_, id); }
  Eigen::Vector3d velocity(int id) const { return Get(v_, id); }
  Eigen::Vector3d force(int id) const { return Get(f_, id); }
  double plastic_deformation(int id) const { return Get(plastic_, id); }
  Eigen::Vector3d& mutable_velocity(int id) { return v_[LiveSlot(id)]; }
  Eigen::Vector3d& mutable_position(int id) { return x_[LiveSlot(id)]; }
  /// Calls f(id, position, velocity) for every live particle, in storage order (cheap: no copies).
  template <class F>
  void ForEachParticle(F&& f) const {
    for (size_t s = 0; s < x_.size(); ++s)
      if (alive_[s]) f(id_of_slot_[s], x_[s], v_[s]);
  }
  /// OpenMP threads from the next step on (the results do not depend on it).
  void set_threads(int threads);
  // all particles, indexed by ID (copies: the storage is kept sorted by cell, not by ID)
  std::vector<Eigen::Vector3d> positions() const;
  std::vector<Eigen::Vector3d> velocities() const;
  std::vector<double> plastic_deformations() const;
  const SoilParams& soil() const { return soil_; }
  double mass() const { return mass_; }
  long neighbour_builds() const { return builds_; }
  /// Of those, the builds forced by an added particle whose neighbour's list had no room left.
  long overflow_builds() const { return overflow_builds_; }
  int contacts() const;  ///< pairs in contact at the last force evaluation
  /// The energies now and the ledger since Finalize() (see EnergyReport: the ledger is kept).
  EnergyReport Energy() const;
  /// Bytes held for the particles, neighbour lists, contact histories and walls.
  size_t MemoryBytes() const;
  Eigen::Vector3d Momentum() const;

 private:
  // The particles live in slots, sorted at every neighbour build by slab and then cell (so that a
  // particle's neighbours sit near it in memory); id_of_slot_ and slot_of_id_ map between slots and
  // the IDs the caller sees. A removed particle's slot is free (id_of_slot_ = -1) until reused;
  // its ID keeps pointing at it (-2 - slot) so its last state stays readable, until the slot is
  // reused (-1).
  template <class T>
  T Get(const std::vector<T>& v, int id) const {
    const int s = slot_of_id_.at(id);
    if (s == -1) return NaNLike(T());
    return v[s >= 0 ? s : -2 - s];
  }
  int LiveSlot(int id) const;
  static double NaNLike(double) { return std::numeric_limits<double>::quiet_NaN(); }
  static Eigen::Vector3d NaNLike(const Eigen::Vector3d&) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  void BuildNeighbours();
  void SortSlots(const std::vector<long>& cell);
  void InsertNeighbours(int p);
  bool InsertPair(int i, int j);
  void RemovePair(int i, int j);
  const TangentialHistory* FindHistory(int i, int j) const;
  EnergyReport Mechanical() const;
  double ParticleEnergy(int i) const;
  double PairEnergy(int i, int k) const;
  void ComputeForces();
  void UpdateWallVertices();
  double MaxWallDisplacement() const;
  void CheckState() const;
  void CheckOverlaps() const;

  SoilParams soil_;
  DemSettings settings_;
  SoilContactLaw law_;
  double mass_ = 0.0, cutoff_ = 0.0;
  Eigen::Vector3d gravity_{0, 0, -9.81};
  double dt_ = 0.0, time_ = 0.0;
  long step_ = 0, builds_ = 0, overflow_builds_ = 0;
  bool finalized_ = false, rebuild_ = true;

  // particles by slot; alive_: 0 free, 1 listed at the last build, 2 added since
  std::vector<Eigen::Vector3d> x_, v_, f_, x_built_;
  std::vector<double> plastic_, adhesion_max_, max_repulsion_, max_tension_, overlap_;
  std::vector<unsigned char> alive_;
  std::vector<int> id_of_slot_, slot_of_id_, free_slots_;  ///< free_slots_ ascending
  int removed_ = 0;
  // half neighbour lists: the partners of the pairs slot i owns, ascending, in
  // nbr_[nbr_begin_[i], nbr_end_[i]), with room up to nbr_cap_[i]; each entry holds that contact's
  // history (from i's side)
  std::vector<int> nbr_begin_, nbr_end_, nbr_cap_, nbr_;
  std::vector<TangentialHistory> hist_;
  std::vector<unsigned char> touching_;
  // the last build's cell grid (the slots of cell c are cell_start_[c] .. cell_start_[c + 1] - 1,
  // at their positions at the build); the slab axis is the slowest-varying one
  Eigen::Vector3d grid_lo_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i grid_dims_ = Eigen::Vector3i::Ones();
  Eigen::Matrix<long, 3, 1> grid_stride_ = Eigen::Matrix<long, 3, 1>::Ones();
  std::vector<int> cell_start_, added_since_build_;
  // slabs: cells_per_slab_ cells (each at least one cutoff) along slab_axis_; a slab's slots from
  // the build are slab_start_[s] .. slab_start_[s + 1] - 1, those added since in slab_added_[s]
  int slab_axis_ = 0, cells_per_slab_ = 1;
  std::vector<int> slab_of_, slab_start_;
  std::vector<std::vector<int>> slab_added_;
  Eigen::Vector3i CellOf(const Eigen::Vector3d& x) const;
  long CellIndex(const Eigen::Vector3i& c) const { return c.cast<long>().dot(grid_stride_); }
  int SlabOfCell(const Eigen::Vector3i& c) const {
    return std::min(c[slab_axis_] / cells_per_slab_, static_cast<int>(slab_start_.size()) - 2);
  }
  bool Owns(int i, int j) const { return slab_of_[i] < slab_of_[j] || (slab_of_[i] == slab_of_[j] && i < j); }
  std::vector<int> NeighbourCandidates(const Eigen::Vector3d& x) const;
  /// Calls f(slot) for every slot the last build put in the 27 cells about cell c.
  template <class F>
  void ForEachSlotNear(const Eigen::Vector3i& c, F&& f) const {
    Eigen::Vector3i q;
    for (q.z() = c.z() - 1; q.z() <= c.z() + 1; ++q.z())
      for (q.y() = c.y() - 1; q.y() <= c.y() + 1; ++q.y())
        for (q.x() = c.x() - 1; q.x() <= c.x() + 1; ++q.x()) {
          if ((q.array() < 0).any() || (q.array() >= grid_dims_.array()).any()) continue;
          const long cell = CellIndex(q);
          for (int j = cell_start_[cell]; j < cell_start_[cell + 1]; ++j) f(j);
        }
  }
  // the energy ledger
  double e0_ = 0.0, wall_work_ = 0.0, exchanged_ = 0.0, wall_power_ = 0.0;
  // walls: world triangles at the last build; per slot the candidate triangles, and per slot and
  // wall one tangential history
  std::vector<DemWall> walls_;
  std::vector<TangentialHistory> wall_hist_;
  std::vector<unsigned char> wall_touching_;
  struct WallTri {
    int wall, face;
  };
  std::vector<SoilContactLaw> wall_law_;                    ///< the law with each wall's friction
  std::vector<std::vector<Eigen::Vector3d>> wall_vertices_, wall_built_vertices_;  ///< world
  std::vector<WallTri> wall_tris_;
  std::vector<int> particle_tri_start_, particle_tris_;  ///< CSR: candidate wall triangles per slot
  struct WallSum {
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    double power = 0.0;
    int contacts = 0;
  };
  std::vector<WallSum> wall_chunk_;  ///< per chunk of slots and wall
};

}  // namespace dem_mobility
