// The rigid tire's surface: rings of vertices around the spin axis (body y), the same mesh for the
// road contact (its vertices) and the soil (its triangles).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

/// Geometry of a rigid tire: a triangle mesh built as rings of vertices around the spin axis
/// (body y), so that only the columns facing the ground need testing.
struct TireGeometry {
  double radius = 0.0, width = 0.0, shoulder_radius = 0.0;
  int n_circ = 0, n_lat = 0;
  std::vector<double> lat_y, lat_r;  ///< per lateral index: y offset and radius
  TriMesh mesh;                      ///< vertex index = column * n_lat + lateral index
  static TireGeometry Make(double radius, double width, double shoulder_radius, int n_circ,
                           int n_lat);
  Eigen::Vector3d Vertex(int col, int j) const { return mesh.vertices[col * n_lat + j]; }
};

}  // namespace dem_mobility::core
