// Small rotation helpers (incremental rotation matrices of the paper's eq. 5).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace dem_mobility::core {

inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// Rotation matrix of the rotation vector `theta` (Rodrigues' formula), the R(dtheta) of eq. 5.
inline Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& theta) {
  const double a2 = theta.squaredNorm();
  double s, c;  // sin(a)/a and (1-cos(a))/a^2
  if (a2 < 1e-12) {
    s = 1.0 - a2 / 6.0;
    c = 0.5 - a2 / 24.0;
  } else {
    const double a = std::sqrt(a2);
    s = std::sin(a) / a;
    c = (1.0 - std::cos(a)) / a2;
  }
  const Eigen::Matrix3d k = Skew(theta);
  return Eigen::Matrix3d::Identity() + s * k + c * k * k;
}

/// Rotation vector of a rotation matrix (inverse of ExpRotation for angles below pi).
inline Eigen::Vector3d LogRotation(const Eigen::Matrix3d& r) {
  const double cos_a = std::clamp((r.trace() - 1.0) * 0.5, -1.0, 1.0);
  const double a = std::acos(cos_a);
  const Eigen::Vector3d w(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  if (a < 1e-6) return 0.5 * w;
  return (a / (2.0 * std::sin(a))) * w;
}

inline Eigen::Matrix3d RotX(double a) {
  return ExpRotation(Eigen::Vector3d(a, 0, 0));
}
inline Eigen::Matrix3d RotY(double a) {
  return ExpRotation(Eigen::Vector3d(0, a, 0));
}
inline Eigen::Matrix3d RotZ(double a) {
  return ExpRotation(Eigen::Vector3d(0, 0, a));
}

/// Projects a nearly orthonormal matrix back onto SO(3) (one Newton step of the polar decomposition).
inline void Reorthonormalize(Eigen::Matrix3d& r) {
  r = r * (1.5 * Eigen::Matrix3d::Identity() - 0.5 * r.transpose() * r);
}

}  // namespace dem_mobility::core
