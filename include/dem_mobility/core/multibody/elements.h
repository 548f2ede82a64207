// Penalty force elements of the multibody core (paper section 2.1, eq. 6-7) and spring-dampers.
//
// Every element is a plain struct: parameters, a little state, and Apply(bodies, dt) that adds its
// forces to the bodies' accumulators. Elements reference bodies by index into the system's list.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/common/table.h"
#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/multibody/rigid_body.h"

namespace dem_mobility::core {

using Bodies = std::vector<RigidBody>;

/// Stability data of one element for the time-step guard (dem-notes section 3.5).
struct StiffnessInfo {
  double omega = 0.0;     ///< undamped angular frequency of the element's mode [rad/s]
  double zeta = 0.0;      ///< damping ratio of that mode
  std::string detail;     ///< what limits it (stiffness, lightest body)
  /// The bodies the mode moves and each one's inverse mass (or inertia) in it, omega^2 = k sum of
  /// them: how the guard shares the mode among them (MultibodySystem::CriticalTimeStep).
  std::vector<std::pair<int, double>> sides;
};

/// Largest inverse effective mass of body `b` for a force at world offset `r` from its COM
/// (over all force directions). Zero for a fixed body.
double InverseEffectiveMass(const RigidBody& b, const Eigen::Vector3d& r);
/// Inverse inertia of body `b` about the world axis `a` (unit); zero for a fixed body.
double InverseInertiaAbout(const RigidBody& b, const Eigen::Vector3d& a_world);

/// Spherical penalty joint: points pa (on a) and pb (on b) coincide (eq. 6-7).
/// Force on b: -(k d + c d_dot), with d = x_pb - x_pa (vector form: isotropic damping).
struct PointJoint {
  std::string name;
  int a = 0, b = 0;
  Eigen::Vector3d ra, rb;  ///< body coordinates relative to each COM
  double k = 0.0, c = 0.0;
  void Apply(Bodies& bodies) const;
  double Gap(const Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Keeps axis ua (body a) perpendicular to ub (body b); with a PointJoint it makes a universal joint.
struct PerpendicularAxes {
  std::string name;
  int a = 0, b = 0;
  Eigen::Vector3d ua, ub;  ///< unit axes in body coordinates
  double k = 0.0, c = 0.0; ///< torsional penalty [N m/rad], [N m s/rad]
  void Apply(Bodies& bodies) const;
  double Violation(const Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Locks the relative orientation of b with respect to a (the orientation part of a fixed or
/// prismatic joint): torque -(k theta + c (w_b - w_a)), theta the relative rotation vector.
struct OrientationLock {
  std::string name;
  int a = 0, b = 0;
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  ///< R_a^T R_b at assembly
  double k = 0.0, c = 0.0;
  void Apply(Bodies& bodies) const;
  double Angle(const Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Point rb on body b stays on the line through ra along u (both in body a): the translational part
/// of a prismatic joint. Optionally drives the position s along the line to `target` (an actuator).
struct LineConstraint {
  std::string name;
  int a = 0, b = 0;
  Eigen::Vector3d ra, u, rb;  ///< u: unit direction in body a coordinates
  double k = 0.0, c = 0.0;
  bool drive = false;         ///< also hold the position along the line at `target`
  double target = 0.0, k_drive = 0.0, c_drive = 0.0;
  void Apply(Bodies& bodies) const;
  double Gap(const Bodies& bodies) const;
  double Position(const Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Linear constraint on spin rates relative to a housing body h:
///   sum_i coeff_i (w_i - w_h) . axis_i = 0,
/// imposed by a penalty on its time integral g (a gear: two terms; an open differential: carrier
/// speed = mean of the side speeds, i.e. terms (+1, +1, -2), which splits torque equally).
struct RotationalCoupling {
  struct Term {
    int body = 0;
    Eigen::Vector3d axis;  ///< unit axis in body coordinates
    double coeff = 0.0;
  };
  std::string name;
  int housing = 0;
  std::vector<Term> terms;
  double k = 0.0, c = 0.0;  ///< [N m/rad], [N m s/rad]
  double g = 0.0;           ///< integrated violation [rad] (state)
  double Rate(const Bodies& bodies) const;
  void Integrate(const Bodies& bodies, double dt) { g += dt * Rate(bodies); }
  void Apply(Bodies& bodies) const;
  double PotentialEnergy(const Bodies&) const { return 0.5 * k * g * g; }
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Twist part of a constant-velocity joint between shafts a and b (with a PointJoint at the joint
/// centre): the spin of b about its axis equals the spin of a about its axis, at any bend angle.
/// The twist angle is measured after rotating b's axis onto a's by the minimal rotation.
struct CvTwist {
  std::string name;
  int a = 0, b = 0;
  Eigen::Vector3d ua, pa, ub, pb;  ///< shaft axes and reference perpendiculars, body coordinates
  double k = 0.0, c = 0.0;
  void Apply(Bodies& bodies) const;
  double Twist(const Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Force along the line between two points: a coil spring (force table of compression), a damper
/// (piecewise-linear in velocity, compression and rebound), and length stops.
/// Used for coil-overs and, with a stiff linear spring, for massless links (rear toe links).
struct SpringDamper {
  std::string name;
  int a = 0, b = 0;
  Eigen::Vector3d ra, rb;
  double free_length = 0.0;
  Table1D spring;           ///< force [N] (compression positive) vs compression [m]; empty: none
  double linear_k = 0.0;    ///< added linear stiffness [N/m] about free_length
  double linear_c = 0.0;    ///< added linear damping [N s/m]
  Table1D damper;           ///< force [N] vs compression rate [m/s] (positive: compressing); empty: none
  double min_length = 0.0, max_length = 0.0;  ///< stops; max_length <= 0: no stops
  double stop_k = 0.0, stop_c = 0.0;
  double Length(const Bodies& bodies) const;
  void Apply(Bodies& bodies) const;
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Torque actuator about an axis of body b, reacting on housing h (drive shaft, brakes).
/// The torque itself is set from outside each step.
struct AxisTorque {
  std::string name;
  int housing = 0, body = 0;
  Eigen::Vector3d axis;     ///< unit axis in body b coordinates
  double torque = 0.0;      ///< applied on b about axis; -torque on h
  bool source = false;      ///< an energy source (an engine): its work is in MultibodySystem::work()
  double RelativeSpeed(const Bodies& bodies) const;
  void Apply(Bodies& bodies) const;
};

}  // namespace dem_mobility::core
