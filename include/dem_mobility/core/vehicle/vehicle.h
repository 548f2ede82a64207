// The 33-body HMMWV-type vehicle of the paper (section 4.1), assembled from a VehicleSpec.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/multibody/multibody_system.h"
#include "dem_mobility/core/vehicle/powertrain.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

/// Wheel order everywhere (kWheelNames, common/exchange.h): front left, front right, rear left, rear right.
enum WheelIndex { kFrontLeft = 0, kFrontRight = 1, kRearLeft = 2, kRearRight = 3 };

/// A vehicle assembled in a MultibodySystem from a VehicleSpec: chassis; per corner upper and
/// lower control arms, upright (knuckle) and wheel; steering rack and two tie rods; drive shaft;
/// per axle pinion, carrier, two side gears and two half shafts. Penalty joints connect them (revolute = two
/// spherical points on the axis); gears, differentials and CV joints are penalty couplings.
///
/// The drive torque request and brake effort are set from outside; every force evaluation clamps
/// the drive torque between the engine-brake and WOT curves at the current drive-shaft speed and
/// turns the brake effort into wheel torques at the current wheel speeds.
class Vehicle {
 public:
  /// Assembles the vehicle `spec` describes with its chassis reference frame at `position` (world),
  /// every body at rest with R = I. The wheels touch nothing: the terrain's wrenches arrive through
  /// SetWheelWrench.
  static std::unique_ptr<Vehicle> Build(const VehicleSpec& spec, const Eigen::Vector3d& position);

  MultibodySystem& system() { return system_; }
  const MultibodySystem& system() const { return system_; }
  const VehicleSpec& spec() const { return spec_; }
  const PowertrainParams& powertrain() const { return spec_.powertrain; }
  const TireGeometry& tire() const { return spec_.tire; }
  const std::string& name() const { return spec_.name; }

  int chassis() const { return chassis_; }
  /// Wheel speed / drive-shaft speed when all wheels turn alike (the final drive ratio).
  double driveline_reduction() const { return spec_.driveline_reduction(); }
  int wheel(int i) const { return wheels_[i]; }
  /// Distance from the ground plane under a wheel to the chassis reference frame at design.
  double design_ride_height() const { return ride_height_; }
  /// Chassis reference-frame origin in world coordinates (the chassis COM minus its offset).
  Eigen::Vector3d ChassisFramePosition() const;

  double ForwardSpeed() const;       ///< chassis COM velocity along the chassis x axis [m/s]
  double Heading() const;            ///< yaw of the chassis x axis from the world x axis, + left [rad]
  double DriveShaftSpeed() const;    ///< relative to the chassis [rad/s]
  double WheelSpeed(int i) const;    ///< spin relative to the upright [rad/s]
  double WheelLoad(int i) const { return wrench_[i].normal_force; }  ///< last terrain normal force [N]
  const WheelWrench& wheel_wrench(int i) const { return wrench_[i]; }
  /// State of wheel i in the world frame (what the terrain is sent).
  WheelState GetWheelState(int i) const;
  /// Applies the terrain's wrench on wheel i (world frame, about its centre) from now on.
  void SetWheelWrench(int i, const WheelWrench& w);
  /// The modes of a wheel-terrain contact with the given stiffness and damping on each wheel (in
  /// its worst direction: the contact point on the rim), for the guard (MultibodySystem::
  /// CriticalTimeStep's `extra`: on each wheel with its joints).
  std::vector<MultibodySystem::BodyMode> WheelContactModes(double stiffness, double damping) const;
  /// The whole vehicle's time-step limit with that contact on its wheels.
  TimeStepLimit CriticalTimeStep(double contact_stiffness, double contact_damping) const {
    return system_.CriticalTimeStep(WheelContactModes(contact_stiffness, contact_damping));
  }

  void SetDriveTorqueRequest(double t) { drive_request_ = t; }
  void SetBrakeEffort(double effort) { brake_effort_ = effort; }
  /// Sets every body moving at `v` along the chassis x axis (the vehicle as built, R = I), the
  /// wheels rolling at v / r and every shaft and gear of the driveline turning as its couplings
  /// and CV joints require (a least-squares solve of their rates with the wheels' spins given):
  /// a vehicle arriving at speed, no coupling or joint strained by it.
  void SetRollingSpeed(double v);
  /// Steering: the rack's position servo to `fraction` of full lock (max_rack_travel; + left).
  void SetSteering(double fraction);
  double AppliedDriveTorque() const;
  double BrakeEffort() const { return brake_effort_; }

  /// The vehicle's energy and its ledger since the system's Finalize: `elastic` includes the brakes'
  /// stick springs; `wall_work` is the terrain's work on the wheels, `exchanged` the engine's work
  /// on the drive shaft and the steering servo's (its rack target moved); `dissipated` = wall_work
  /// + exchanged - (Total() - Total() at Finalize): what the dampers, brakes and differentials
  /// took. Never negative beyond the integrator's error in a stable run.
  EnergyReport Energy() const;
  /// Its state in a checkpoint (common/state_archive.h): the multibody system, the brakes, the
  /// requests in force and the wheels' last wrenches.
  template <class Ar>
  void Io(Ar& ar);

 private:
  friend class VehicleAssembler;
  Vehicle() = default;
  void ApplyPowertrain(MultibodySystem& sys);

  MultibodySystem system_;
  VehicleSpec spec_;
  int chassis_ = -1;
  std::array<int, 4> wheels_{};
  std::array<int, 4> brakes_{};   ///< indices into system_.torques
  std::array<double, 4> brake_angle_{}, brake_anchor_{};  ///< wheel angle rel. upright; brake state
  int drive_ = -1;                ///< index into system_.torques
  Eigen::Vector3d chassis_com_offset_ = Eigen::Vector3d::Zero();
  double ride_height_ = 0.0;
  double drive_request_ = 0.0, brake_effort_ = 0.0;
  double servo_work_ = 0.0;       ///< the steering servo's work: its springs' energy when the target moved
  int rack_ = -1;                 ///< index into system_.line_constraints (the rack's prismatic joint)
  std::array<WheelWrench, 4> wrench_{};
};

}  // namespace dem_mobility::core
