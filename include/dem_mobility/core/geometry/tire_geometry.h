// The rigid tire's surface: rings of vertices around the spin axis (body y), the same mesh for the
// road contact (its vertices) and the soil (its triangles, closed by two sidewalls).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

class YamlReader;

/// Tread lugs: `count` bars across the tread, `height` proud of the carcass, covering `fraction`
/// of the circumference (0 lugs: a smooth tread).
struct TireLugs {
  int count = 0;
  double height = 0.0, fraction = 0.5;
};

/// Geometry of a rigid tire: a triangle mesh built as rings of vertices around the spin axis
/// (body y), so that only the columns facing the ground need testing. `radius` is the outer
/// radius (the lugs' tops when there are lugs).
struct TireGeometry {
  double radius = 0.0, width = 0.0, shoulder_radius = 0.0;
  double rim_radius = 0.0;  ///< inner edge of the sidewalls (the soil surface's hub hole)
  int n_circ = 0, n_lat = 0, sidewall_rings = 0;
  TireLugs lugs;
  std::vector<double> lat_y, lat_r;  ///< per lateral index: y offset and radius (lug tops)
  TriMesh mesh;                      ///< the tread; vertex index = column * n_lat + lateral index
  std::string mesh_file;             ///< when the soil surface was loaded from a file
  TriMesh soil_mesh;                 ///< the closed surface the soil touches: tread and sidewalls
  static TireGeometry Make(double radius, double width, double shoulder_radius, int n_circ, int n_lat,
                           const TireLugs& lugs = TireLugs(), double rim_radius = 0.0, int sidewall_rings = 4);
  /// Reads a tire file (radius, width, shoulder_radius, n_circ, n_lat; optional rim_radius,
  /// sidewall_rings, lugs: {count, height, fraction}, soil_mesh: an OBJ file for the soil
  /// surface). ConfigError names the file and key.
  static TireGeometry Read(const YamlReader& y);
  Eigen::Vector3d Vertex(int col, int j) const { return mesh.vertices[col * n_lat + j]; }
};

/// Reads the triangles of a Wavefront OBJ file (`v` and `f` lines; polygons are fanned).
/// ConfigError naming the file and line for anything else it cannot read.
TriMesh LoadObjMesh(const std::string& path);

}  // namespace dem_mobility::core
