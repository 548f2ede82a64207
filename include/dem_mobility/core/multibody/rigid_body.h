// A rigid body of the explicit multibody core (paper eq. 1-2).
#pragma once

#include <Eigen/Core>
#include <string>

namespace dem_mobility::core {

/// Lumped mass at the centre of mass, inertia in the body frame (so it is constant, eq. 2).
/// Translational state in the global frame, angular velocity in the body frame.
struct RigidBody {
  std::string name;
  bool fixed = false;  ///< ground: never integrated, infinite mass

  // parameters
  double mass = 0.0;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();      ///< body frame, about the COM
  double inv_mass = 0.0;
  Eigen::Matrix3d inv_inertia = Eigen::Matrix3d::Zero();
  double min_inertia = 0.0;                               ///< smallest principal moment

  // state
  Eigen::Vector3d x = Eigen::Vector3d::Zero();            ///< COM position, world
  Eigen::Vector3d v = Eigen::Vector3d::Zero();            ///< COM velocity, world
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();        ///< body -> world rotation
  Eigen::Vector3d w = Eigen::Vector3d::Zero();            ///< angular velocity, body frame

  // per-step cache and accumulators (computed by the system)
  Eigen::Vector3d w_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();        ///< total force, world
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();       ///< total torque about the COM, world
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();        ///< last acceleration, world
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();        ///< last angular acceleration, body

  // externally applied wrench (e.g. from a terrain), world frame, about the COM; kept until changed
  Eigen::Vector3d ext_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d ext_torque = Eigen::Vector3d::Zero();

  /// World position of a point given in body coordinates relative to the COM.
  Eigen::Vector3d PointWorld(const Eigen::Vector3d& r_body) const { return x + R * r_body; }
  /// World velocity of the point at world offset `r` from the COM.
  Eigen::Vector3d VelocityAt(const Eigen::Vector3d& r) const { return v + w_world.cross(r); }
  /// Adds force `f` (world) acting at world offset `r` from the COM.
  void AddForceAt(const Eigen::Vector3d& f, const Eigen::Vector3d& r) {
    force += f;
    torque += r.cross(f);
  }
  /// Kinetic energy (translational + rotational).
  double KineticEnergy() const { return 0.5 * mass * v.squaredNorm() + 0.5 * w.dot(inertia * w); }
  /// The state in a checkpoint (common/state_archive.h): the motion and the last step's forces and
  /// accelerations (the parameters are the built body's).
  template <class Ar>
  void Io(Ar& ar) {
    ar(x, v, R, w, w_world, force, torque, accel, alpha, ext_force, ext_torque);
  }
  /// Angular momentum about the COM, world frame.
  Eigen::Vector3d AngularMomentumWorld() const { return R * (inertia * w); }
};

}  // namespace dem_mobility::core
