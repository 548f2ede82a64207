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

  /// A mode acting on one body from outside the elements (a terrain contact on a wheel).
  struct BodyMode {
    int body = 0;
    std::string name;
    StiffnessInfo mode;
  };
  /// The time-step guard. Each element's own mode has omega_e^2 = k (w_a + w_b) (w: the inverse
  /// masses of its bodies in its worst direction); the elements on one body act on it together, and
  /// the system's highest frequency is at most the largest over the bodies of sqrt(sum of the
  /// shares of omega_e^2 of the elements on the body), body a's share being
  /// omega_e^2 sqrt(w_a) (sqrt(w_a) + sqrt(w_b)) / (w_a + w_b) (Cauchy-Schwarz on each element's
  /// energy: k |u_a - u_b|^2 <= k (w_a |q_a|^2 / t + w_b |q_b|^2 / (1 - t)) for any t in (0, 1);
  /// t = sqrt(w_a) / (sqrt(w_a) + sqrt(w_b))). So the critical step is the smallest over the bodies of
  /// (2 / omega)(sqrt(1 + zeta^2) - zeta) at that omega, with the dampers added as the springs are
  /// (zeta = sum zeta_e omega_e / omega): a bound that holds for the assembled system, where the stiffest element alone
  /// is not one (the vehicle blew up at 0.7 of that element's step: docs/stability.md). `extra`:
  /// modes on bodies from outside (a terrain's contact on the wheels).
  TimeStepLimit CriticalTimeStep(const std::vector<BodyMode>& extra = {}) const;
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
  /// The work done on the system since Finalize by what is outside it: the external wrenches
  /// (ext_force, ext_torque: a terrain's) and the AxisTorques marked as sources (an engine). Each
  /// step adds the mean of a force's values at the step's two evaluations times the step's motion
  /// (dt times the half-step velocity): the form in which velocity Verlet's kinetic energy follows
  /// the work exactly, so that Energy() less the energy at Finalize less this work is what the
  /// dampers, brakes and friction took, down to the integrator's error.
  struct Work {
    using StateBulk = void;
    double external = 0.0;  ///< ext_force and ext_torque [J]
    double sources = 0.0;   ///< AxisTorques with source = true [J]
  };
  const Work& work() const { return work_; }
  /// Energy().Total() at Finalize [J].
  double initial_energy() const { return e0_; }
  /// Total mass of the movable bodies and their centre of mass.
  double TotalMass() const;
  Eigen::Vector3d CenterOfMass() const;
  /// Its state in a checkpoint (common/state_archive.h): the bodies' motion, the elements' state
  /// (couplings' integrals, torques, actuator targets, contact anchors), the clock and the work
  /// ledger; the bodies and elements themselves are the built system's (their numbers are checked).
  template <class Ar>
  void Io(Ar& ar);

 private:
  /// The forces at the current state; `accumulate`: add the step's work to work_ (not at Finalize).
  void ComputeForces(bool accumulate);
  void CheckFinite() const;
  Bodies bodies_;
  Work work_;
  double e0_ = 0.0;
  std::vector<Eigen::Vector3d> last_ext_force_, last_ext_torque_;  ///< at the previous evaluation
  std::vector<double> last_source_torque_;
  Eigen::Vector3d gravity_{0, 0, -9.81};
  double dt_ = 0.0, time_ = 0.0;
  long step_ = 0;
  bool finalized_ = false;
};

}  // namespace dem_mobility::core
