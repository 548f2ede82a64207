// The explicit DEM solver for the cohesive soil (paper section 2.3): point particles (3
// translational DOF) with a contact diameter, the soil law of soil_law.h between every pair,
// velocity Verlet (the explicit member of the multibody core's trapezoidal family), a Cartesian
// cell grid with a Verlet skin, and OpenMP.
//
// Determinism: each pair's force is computed once (half neighbour list) and stored; then every
// particle gathers its pairs' forces in a fixed order (the pairs it is first in, then those it is
// second in, ascending). So the forces are exactly equal and opposite, no thread writes data
// another thread writes, and the result is bit-for-bit the same for any number of threads.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/multibody/trimesh.h"

namespace dem_mobility {

/// Energy bookkeeping of the particles.
struct DemEnergy {
  double kinetic = 0.0;
  double gravitational = 0.0;  ///< -m g . x summed
  double elastic = 0.0;        ///< repulsion and adhesion branches and tangential springs
  double Total() const { return kinetic + gravitational + elastic; }
};

/// The time-step guard of the particles: the stiffest branch over the particle mass at the largest
/// coordination, with its damping.
struct DemStepLimit {
  double dt_crit = 0.0;
  std::string detail;
};

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
  double max_overlap = 0.1;     ///< watchdog: largest overlap / diameter before the run stops
  int max_coordination = 12;    ///< contacts per particle assumed by the time-step guard
};

class DemSystem {
 public:
  DemSystem(const SoilParams& soil, const DemSettings& settings);

  /// Adds a particle (before or between steps); returns its index.
  int AddParticle(const Eigen::Vector3d& x, const Eigen::Vector3d& v = Eigen::Vector3d::Zero());
  void set_gravity(const Eigen::Vector3d& g) { gravity_ = g; }
  /// Adds a wall (before Finalize); returns its index. A moving wall gets its pose and velocity
  /// set through mutable_wall() before each Step (prescribed motion, or a multibody body's state).
  int AddWall(DemWall wall);
  DemWall& mutable_wall(int w) { return walls_[w]; }
  const DemWall& wall(int w) const { return walls_[w]; }
  int num_walls() const { return static_cast<int>(walls_.size()); }

  DemStepLimit CriticalTimeStep() const;
  /// Refuses (ConfigError naming the limit) a step above the critical one; computes the forces.
  void Finalize(double dt);
  /// One step. Throws SimulationError naming the step, the particle and the quantity when a
  /// watchdog trips (a non-finite state or force, an overlap beyond max_overlap, a particle moving
  /// more than half the skin in one step); the state at the failure stays readable (for saving).
  void Step();

  int size() const { return static_cast<int>(x_.size()); }
  long step_count() const { return step_; }
  double time() const { return time_; }
  double dt() const { return dt_; }
  const std::vector<Eigen::Vector3d>& positions() const { return x_; }
  const std::vector<Eigen::Vector3d>& velocities() const { return v_; }
  const std::vector<Eigen::Vector3d>& forces() const { return f_; }
  const std::vector<double>& plastic_deformation() const { return plastic_; }
  Eigen::Vector3d& mutable_velocity(int i) { return v_[i]; }
  Eigen::Vector3d& mutable_position(int i) { return x_[i]; }
  const SoilParams& soil() const { return soil_; }
  double mass() const { return mass_; }
  long neighbour_builds() const { return builds_; }
  int contacts() const;  ///< pairs in contact at the last force evaluation
  DemEnergy Energy() const;
  /// Bytes held for the particles, neighbour lists, contact histories and walls.
  size_t MemoryBytes() const;
  Eigen::Vector3d Momentum() const;

 private:
  void BuildNeighbours();
  void ComputeForces();
  void ComputeWallForces();
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
  long step_ = 0, builds_ = 0;
  bool finalized_ = false, rebuild_ = true;

  // particles
  std::vector<Eigen::Vector3d> x_, v_, f_, x_built_;
  std::vector<double> plastic_, adhesion_max_, max_repulsion_, overlap_;
  // half neighbour list (CSR over the first particle, second ascending) with each pair's contact
  // history and last force; the reverse list gives each particle the pairs it is second in
  std::vector<int> nbr_start_, nbr_, rev_start_, rev_;
  std::vector<TangentialHistory> hist_;
  std::vector<unsigned char> touching_;
  std::vector<Eigen::Vector3d> pair_force_;  ///< on the first particle of the pair
  std::vector<double> pair_rep_, pair_overlap_;
  // walls: world triangles at the last build, binned into the particle grid; per particle and
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
  std::vector<int> particle_tri_start_, particle_tris_;  ///< CSR: candidate wall triangles per particle
  std::vector<Eigen::Vector3d> wall_force_, wall_moment_;  ///< per particle and wall, summed per wall
};

}  // namespace dem_mobility
