// The explicit multibody system: bodies, penalty elements, contacts, gravity, and the integrator.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/multibody/contact.h"
#include "dem_mobility/core/multibody/elements.h"
#include "dem_mobility/core/multibody/rigid_body.h"

namespace dem_mobility::core {

/// Bodies and force elements integrated by velocity Verlet, the explicit member of the trapezoidal
/// family (paper eq. 3-5): the velocity update is eq. 3a/4a, positions use x + dt v + dt^2/2 a, and
/// the orientation is updated by incremental rotation matrices, R <- R R(dt w) (eq. 5).
/// Body 0 is the fixed ground.
///
/// Lifecycle: add bodies and elements, Finalize(dt) (checks the step against the guard and computes
/// the initial forces), then Step() repeatedly. Stepping never allocates.
class MultibodySystem {
 public:
  MultibodySystem();

  int AddBody(RigidBody body);  ///< checks mass and inertia; returns the index
  int FindBody(const std::string& name) const;  ///< -1 if absent
  const RigidBody& body(int i) const { return bodies_[i]; }
  RigidBody& mutable_body(int i) { return bodies_[i]; }
  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  const Bodies& bodies() const { return bodies_; }

  void set_gravity(const Eigen::Vector3d& g) { gravity_ = g; }
  const Eigen::Vector3d& gravity() const { return gravity_; }

  std::vector<PointJoint> point_joints;
  std::vector<PerpendicularAxes> perpendicular_axes;
  std::vector<OrientationLock> orientation_locks;
  std::vector<LineConstraint> line_constraints;
  std::vector<RotationalCoupling> couplings;
  std::vector<CvTwist> cv_twists;
  std::vector<SpringDamper> springs;
  std::vector<AxisTorque> torques;
  std::vector<PointSetContact> point_contacts;

  /// Called after the element forces and before the accelerations, every force evaluation
  /// (for controllers that set AxisTorque values from the current state).
  std::function<void(MultibodySystem&)> pre_force_hook;

  /// The time-step guard: the critical step of every element from its stiffness and the bodies it
  /// connects (omega^2 = k (1/m_a + 1/m_b), damping factor sqrt(1+z^2)-z); returns the smallest.
  TimeStepLimit CriticalTimeStep() const;
  /// Refuses (ConfigError naming the element and the limit) a dt above the critical step, then
  /// computes the forces at the initial state. `check_step = false` skips the guard (only for
  /// stability studies such as the integrator tests).
  void Finalize(double dt, bool check_step = true);
  /// One explicit step (BeginStep then EndStep). Throws SimulationError on a non-finite state.
  void Step();
  /// The first half of a step: half kick with the current forces, drift to t + dt. Between the two
  /// halves the positions and half-step velocities are those the new forces are evaluated at, so a
  /// co-simulation peer (the terrain) computes its wrenches from them and sets ext_force/ext_torque.
  void BeginStep();
  /// The second half: forces at the new state, second half kick, finiteness check.
  void EndStep();

  double time() const { return time_; }
  long step_count() const { return step_; }
  double dt() const { return dt_; }
  EnergyReport Energy() const;
  /// Total mass of the movable bodies and their centre of mass.
  double TotalMass() const;
  Eigen::Vector3d CenterOfMass() const;

 private:
  void ComputeForces();
  void CheckFinite() const;
  Bodies bodies_;
  Eigen::Vector3d gravity_{0, 0, -9.81};
  double dt_ = 0.0, time_ = 0.0;
  long step_ = 0;
  bool finalized_ = false;
};

}  // namespace dem_mobility::core
