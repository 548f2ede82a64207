// A static terrain surface with a uniform 2-D grid index (the rigid road's triangles).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

/// A static terrain surface: a triangle mesh that faces up (+z of its frame), with a uniform grid
/// over x-y so that a point query only touches the triangles of one cell. Penetration is measured
/// along each triangle's normal. Gravity, not the mesh, carries the grade.
class TerrainMesh {
 public:
  /// `cell`: grid cell size [m]; `max_depth`: deepest penetration that still counts as contact
  /// (beyond it the point is taken to be behind the surface, not in it).
  TerrainMesh(TriMesh mesh, double cell, double max_depth);

  struct Hit {
    double depth = 0.0;           ///< penetration (> 0 in contact)
    Eigen::Vector3d normal;       ///< outward unit normal of the triangle
    int face = -1;
  };
  /// Deepest penetrating triangle under point p (x-y projection), if any.
  bool Query(const Eigen::Vector3d& p, Hit* hit) const;
  /// The plane (unit normal n, offset n.p) under the whole x-y box [lo, hi], if every cell the box
  /// touches is tiled by triangles of that one plane; lets a caller skip per-triangle tests.
  bool BoxPlane(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, Eigen::Vector3d* n, double* offset) const;
  /// Highest surface point over the x-y box [lo, hi] (conservative: the cells' maxima).
  double MaxHeight(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;

  const TriMesh& mesh() const { return mesh_; }
  double max_depth() const { return max_depth_; }

 private:
  struct Face {
    Eigen::Vector3d n;  ///< unit normal
    double offset;      ///< n . p0
    Eigen::Vector2d o;  ///< x-y of vertex 0
    Eigen::Matrix2d inv;///< maps (p - p0).xy to barycentric (l1, l2)
  };
  int CellIndex(int ix, int iy) const { return iy * nx_ + ix; }
  TriMesh mesh_;
  std::vector<Face> faces_;
  double cell_, max_depth_;
  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_start_;  ///< CSR: faces of cell i are cell_faces_[cell_start_[i]..[i+1])
  std::vector<int> cell_faces_;
  std::vector<double> cell_zmax_;
  std::vector<signed char> cell_planar_;   ///< 1: the cell is tiled by coplanar triangles
  std::vector<Eigen::Vector4d> cell_plane_;
};

}  // namespace dem_mobility::core
