// What the vehicle nodelet shows: tf of every body, chassis odometry, body shapes, wheel force
// arrows and a speed label. Display and message conversion only.
#pragma once

#include <string>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "dem_mobility/core/mobility/vehicle_cosim.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

/// map -> world (the slope frame of `gravity`): the grade as a pitch and a side slope as a roll, so
/// that gravity points down in map.
geometry_msgs::TransformStamped SlopeTransform(const Eigen::Vector3d& gravity, const ros::Time& stamp,
                                               const std::string& map, const std::string& world);
/// world -> base (the chassis reference frame), and base -> each other body (its COM frame, named
/// after the body).
tf2_msgs::TFMessage BodyTransforms(const Vehicle& v, const ros::Time& stamp, const std::string& world,
                                   const std::string& base);
/// Chassis pose in world; twist of the base frame in the base frame (nav_msgs convention).
nav_msgs::Odometry ChassisOdometry(const Vehicle& v, const ros::Time& stamp, const std::string& world,
                                   const std::string& base);
/// Frame-locked shapes of the bodies (chassis box, wheels, other bodies as spheres by mass).
visualization_msgs::MarkerArray BodyMarkers(const Vehicle& v, const ros::Time& stamp, const std::string& base);
/// Wheel force arrows (force_scale m per N), the joint skeleton and a label with time and speed.
visualization_msgs::MarkerArray LiveMarkers(const VehicleCoSim& sim, const ros::Time& stamp, const std::string& world,
                                            double force_scale);

}  // namespace dem_mobility
