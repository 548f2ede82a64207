// Triangle meshes: a plain mesh, a flat road, and the closest point of a triangle.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace dem_mobility::core {

/// A plain triangle mesh (vertices and faces, counter-clockwise seen from outside).
struct TriMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;
  Eigen::Vector3d FaceNormal(size_t f) const;
};

/// A flat rectangular road of triangles in the z = 0 plane: [x0, x0+length] x [-width/2, width/2],
/// split into cells of `cell` metres, two triangles each.
TriMesh MakeFlatRoad(double x0, double length, double width, double cell);

/// The point of triangle abc closest to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

}  // namespace dem_mobility::core
