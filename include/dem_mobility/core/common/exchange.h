// What the vehicle and the terrain (and the driver) exchange in the lock-step co-simulation, in
// core types. The ROS layer converts these one to one into msg/WheelStates, msg/WheelWrenches,
// msg/DriverInput and msg/DriverCommand (all doubles, so the conversion is exact and a run through
// nodelets gives the same numbers as the in-process runner).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

namespace dem_mobility::core {

/// The wheels, in the order of every exchange, message and result: front left, front right, rear
/// left, rear right.
constexpr int kWheels = 4;
constexpr const char* kWheelNames[kWheels] = {"fl", "fr", "rl", "rr"};

/// State of one wheel in the simulation's world frame: centre, orientation, velocities.
struct WheelState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< of the centre [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< world frame [rad/s]
  template <class Ar>
  void Io(Ar& ar) {
    ar(position, orientation, velocity, angular_velocity);
  }
};

/// The terrain's wrench on one wheel, world frame, about the wheel centre.
struct WheelWrench {
  using StateBulk = void;  // (a checkpoint copies it as bytes: common/state_archive.h)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< [N]
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< [N m]
  double sinkage = 0.0;       ///< deepest penetration [m]
  int contacts = 0;           ///< contact points in this evaluation
  double normal_force = 0.0;  ///< sum of the normal contact forces [N]
  /// Upper bound of the contact's translational stiffness on the wheel [N/m] and its damping
  /// [N s/m]: the vehicle's time-step guard checks its step against them.
  double stiffness = 0.0, damping = 0.0;
};

/// What a terrain file says it is, without building it (for results and displays).
struct TerrainDescription {
  std::string file;
  std::string model;    ///< its `model:` (rigid_road, ...)
  double cone_index = std::numeric_limits<double>::quiet_NaN();  ///< soil strength [psi]
  /// The terrain's own time step [s] (a DEM soil's; 0: none): the exchanges must come at whole
  /// multiples of it.
  double time_step = 0.0;
  std::string fidelity;  ///< the terrain's fidelity level (empty: none)
};

/// Vehicle -> driver at every control step.
struct DriverInput {
  long step = 0;                  ///< vehicle step index
  double time = 0.0;              ///< since the driver's start [s]
  double period = 0.0;            ///< control period [s]
  double forward_speed = 0.0;     ///< [m/s]
  double drive_shaft_speed = 0.0; ///< [rad/s]
  double lateral_offset = 0.0;    ///< [m] the chassis frame from the start line (the x axis), + left
  double heading = 0.0;           ///< [rad] the chassis x axis's yaw from the start line, + left
};

}  // namespace dem_mobility::core
