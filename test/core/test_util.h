// Helpers shared by the core tests.
#pragma once

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/multibody/multibody_system.h"

namespace dem_mobility::core::test {

inline RigidBody MakeBody(const std::string& name, double m, const Eigen::Vector3d& inertia,
                          const Eigen::Vector3d& x = Eigen::Vector3d::Zero()) {
  RigidBody b;
  b.name = name;
  b.mass = m;
  b.inertia = inertia.asDiagonal();
  b.x = x;
  return b;
}

inline PointJoint MakePoint(const MultibodySystem& s, int a, int b, const Eigen::Vector3d& p, double k, double c) {
  PointJoint j;
  j.name = "point";
  j.a = a;
  j.b = b;
  j.ra = s.body(a).R.transpose() * (p - s.body(a).x);
  j.rb = s.body(b).R.transpose() * (p - s.body(b).x);
  j.k = k;
  j.c = c;
  return j;
}

}  // namespace dem_mobility::core::test
