// The vehicle as described by its YAML files (config/vehicles/<name>/vehicle.yaml and the files it
// names), checked, and the figures derived from it without assembling the bodies.
#pragma once

#include <Eigen/Core>
#include <string>

#include "dem_mobility/core/common/table.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/vehicle/powertrain.h"

namespace dem_mobility::core {

/// Stiffness and damping of a penalty element (eq. 6-7): [N/m, N s/m] or [N m/rad, N m s/rad].
struct Penalty {
  double k = 0.0, c = 0.0;
};

/// Mass [kg] and inertia about the centre of mass [kg m^2] of a body, in body (= vehicle) axes.
struct MassProperties {
  double mass = 0.0;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

/// A uniform rod between two points given by the assembly: mass [kg] and radius [m].
struct RodSpec {
  double mass = 0.0, radius = 0.0;
};

/// One axle's double-wishbone suspension, left side, relative to the suspension reference point
/// (x_offset along the chassis x axis); the right side is its mirror image (y -> -y).
struct SuspensionSpec {
  /// Left-side points [m]; uca / lca: upper / lower control arm.
  struct Hardpoints {
    Eigen::Vector3d spindle, upright, uca_front, uca_back, uca_upright, lca_front, lca_back, lca_upright,
        shock_chassis, shock_arm, spring_chassis, spring_arm, tierod_chassis, tierod_upright;
  };
  /// Coil spring between chassis and lower arm, with bump and rebound stops.
  struct Spring {
    double free_length = 0.0;
    Table1D force_table;  ///< compression [m] -> force [N]
    double min_length = 0.0, max_length = 0.0;
    double stop_k = 0.0, stop_c = 0.0;
  };

  double x_offset = 0.0;  ///< [m] suspension reference point along the chassis x axis
  Hardpoints hardpoints;
  MassProperties upright, uca, lca, wheel;
  RodSpec tierod;     ///< steered (front) axle only: the tie rod from the rack end to the upright
  Penalty toe_link;   ///< unsteered (rear) axle only: the massless link in place of the tie rod
  Spring spring;
  Table1D damper_table;  ///< shock: compression rate [m/s] (positive compressing) -> force [N]

  /// A left-side point `left` of this suspension moved to the corner on `side` (0 left, 1 right),
  /// in the chassis frame: shifted by x_offset, mirrored on the right.
  Eigen::Vector3d Corner(const Eigen::Vector3d& left, int side) const {
    const double s = side == 0 ? 1.0 : -1.0;
    return Eigen::Vector3d(left.x() + x_offset, s * left.y(), left.z());
  }
};

/// Rack-and-pinion steering: the rack slides along y in the chassis between the front tie rods.
struct SteeringSpec {
  RodSpec rack;
  double max_rack_travel = 0.0;  ///< [m] full lock
  Penalty actuator;              ///< servo holding the rack position
  Penalty spin_lock;             ///< holds the rack's spin about its own axis
};

/// How a differential joins its outputs: `kOpen` (carrier speed = mean of the two output speeds,
/// equal torque split) or `kLocked` (each output turns with the carrier, any torque split).
enum class Differential { kOpen, kLocked };

/// Drive shaft and per axle pinion, carrier, two side gears and two half shafts. The drive shaft
/// drives both pinions directly (centre locked, the paper's) or is the carrier of an open centre
/// differential between them.
struct DrivelineSpec {
  Differential centre_differential = Differential::kLocked;  ///< between the front and rear pinions
  Differential axle_differentials = Differential::kOpen;     ///< between the side gears of each axle
  double final_drive_ratio = 0.0;  ///< carrier speed / pinion speed
  RodSpec drive_shaft;
  MassProperties pinion;
  double pinion_offset = 0.0;      ///< [m] from the axle centre toward the vehicle centre
  MassProperties carrier;
  MassProperties side_gear;
  double side_gear_offset = 0.0;   ///< [m] from the axle centre along y
  RodSpec half_shaft;
  double half_shaft_inner_offset = 0.0;  ///< [m] inner CV joint from the axle centre along y
  double half_shaft_outer_inset = 0.0;   ///< [m] outer CV joint inboard of the spindle
};

/// Chassis body: the sprung mass includes the driveline and steering parts it carries.
struct ChassisSpec {
  double sprung_mass = 0.0;                                    ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();               ///< [m] in the chassis reference frame
  Eigen::Vector3d inertia_per_kg = Eigen::Vector3d::Zero();    ///< principal moments / mass [m^2]
};

/// Everything the vehicle files say, checked. Vehicle::Build assembles the bodies from it.
struct VehicleSpec {
  std::string name;
  double wheelbase = 0.0;  ///< [m] equal to the suspensions' x_offset difference
  Penalty point_penalty;       ///< spherical / revolute / bracket points and the rack's line
  Penalty rotational_penalty;  ///< gears, differentials, CV twists
  ChassisSpec chassis;
  SuspensionSpec suspension_front, suspension_rear;
  SteeringSpec steering;
  DrivelineSpec driveline;
  PowertrainParams powertrain;
  TireGeometry tire;

  /// Reads `file` and the files it names; throws ConfigError naming the file, the key path and the
  /// value of any bad, missing or unknown input. `open` (empty: YamlReader::Load) opens `file` and
  /// each file it names.
  static VehicleSpec Load(const std::string& file, const YamlOpener& open = {});

  const SuspensionSpec& suspension(int axle) const { return axle == 0 ? suspension_front : suspension_rear; }
  /// Mass of the parts the chassis carries (rack, drive shaft, both axles' differential bodies).
  double CarriedMass() const;
  /// Mass of the chassis body: the sprung mass less the parts it carries.
  double ChassisBodyMass() const { return chassis.sprung_mass - CarriedMass(); }
  /// Height [m] of the axle centres (differentials) in the chassis frame: the rear spindles' height.
  double AxleHeight() const { return suspension_rear.hardpoints.spindle.z(); }
  /// Mass of the assembled vehicle, summed body by body in the assembly's order: equal to the
  /// built MultibodySystem's TotalMass() to the last bit.
  double TotalMass() const;
  double wheel_radius() const { return tire.radius; }
  /// Wheel speed / drive-shaft speed when all wheels turn alike (the final drive ratio).
  double driveline_reduction() const { return driveline.final_drive_ratio; }
};

}  // namespace dem_mobility::core
