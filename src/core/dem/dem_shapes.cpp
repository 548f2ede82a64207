#include "dem_mobility/core/dem/dem_shapes.h"

#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

void CheckShape(const std::string& name, double a, double b, int segments) {
  DM_THROW_UNLESS(a > 0.0 && b > 0.0 && std::isfinite(a) && std::isfinite(b), "shape '", name,
                  "': sizes must be finite and > 0 (", a, ", ", b, ")");
  DM_THROW_UNLESS(segments >= 3 && segments <= 4096, "shape '", name, "': segments ", segments,
                  " must lie in [3, 4096]");
}

/// A ring of `segments` points of radius r at height z (counter-clockwise seen from +z).
void AddRing(TriMesh* m, double r, double z, int segments) {
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    m->vertices.emplace_back(r * std::cos(a), r * std::sin(a), z);
  }
}

/// Fan of a ring starting at `first` about the vertex `centre`; `up` orients the faces to +z.
void AddFan(TriMesh* m, int centre, int first, int segments, bool up) {
  for (int k = 0; k < segments; ++k) {
    const int a = first + k, b = first + (k + 1) % segments;
    if (up) m->faces.push_back({centre, a, b});
    else m->faces.push_back({centre, b, a});
  }
}

/// Side faces between two rings of `segments` points, outward.
void AddBand(TriMesh* m, int lower, int upper, int segments) {
  for (int k = 0; k < segments; ++k) {
    const int a = lower + k, b = lower + (k + 1) % segments, c = upper + (k + 1) % segments, d = upper + k;
    m->faces.push_back({a, b, c});
    m->faces.push_back({a, c, d});
  }
}

}  // namespace

std::vector<DemWall> MakeOpenBoxWalls(double L, double W, double H) {
  CheckShape("box", L, W, 3);
  CheckShape("box", H, H, 3);
  return {MakeQuadWall("floor", {0, 0, 0}, {L, 0, 0}, {0, W, 0}), MakeQuadWall("x0", {0, 0, 0}, {0, 0, H}, {0, W, 0}),
          MakeQuadWall("x1", {L, 0, 0}, {0, W, 0}, {0, 0, H}), MakeQuadWall("y0", {0, 0, 0}, {L, 0, 0}, {0, 0, H}),
          MakeQuadWall("y1", {0, W, 0}, {0, 0, H}, {L, 0, 0})};
}

DemWall MakeDiskWall(const std::string& name, double radius, int segments) {
  CheckShape(name, radius, radius, segments);
  DemWall w;
  w.name = name;
  w.mesh.vertices.emplace_back(0.0, 0.0, 0.0);
  AddRing(&w.mesh, radius, 0.0, segments);
  AddFan(&w.mesh, 0, 1, segments, true);
  return w;
}

std::vector<DemWall> MakeCylinderSideWalls(const std::string& name, double radius, double height, int segments) {
  CheckShape(name, radius, height, segments);
  const double r = radius / std::cos(M_PI / segments);  // corners outside, flats at `radius`
  std::vector<DemWall> walls;
  for (int k = 0; k < segments; ++k) {
    const double a0 = 2.0 * M_PI * k / segments, a1 = 2.0 * M_PI * (k + 1) / segments;
    const Vector3d p0(r * std::cos(a0), r * std::sin(a0), 0.0), p1(r * std::cos(a1), r * std::sin(a1), 0.0);
    walls.push_back(MakeQuadWall(name + "_" + std::to_string(k), p0, p1 - p0, Vector3d(0, 0, height)));
  }
  return walls;
}

DemWall MakeConeWall(const std::string& name, double base_radius, double length, int segments) {
  CheckShape(name, base_radius, length, segments);
  DemWall w;
  w.name = name;
  w.mesh.vertices.emplace_back(0.0, 0.0, 0.0);       // tip
  w.mesh.vertices.emplace_back(0.0, 0.0, length);    // base centre
  AddRing(&w.mesh, base_radius, length, segments);
  for (int k = 0; k < segments; ++k)  // the mantle, outward
    w.mesh.faces.push_back({0, 2 + (k + 1) % segments, 2 + k});
  AddFan(&w.mesh, 1, 2, segments, true);  // the base, facing up
  return w;
}

DemWall MakeRodWall(const std::string& name, double radius, double length, int segments) {
  CheckShape(name, radius, length, segments);
  DemWall w;
  w.name = name;
  w.mesh.vertices.emplace_back(0.0, 0.0, 0.0);
  w.mesh.vertices.emplace_back(0.0, 0.0, length);
  AddRing(&w.mesh, radius, 0.0, segments);
  AddRing(&w.mesh, radius, length, segments);
  AddFan(&w.mesh, 0, 2, segments, false);
  AddFan(&w.mesh, 1, 2 + segments, segments, true);
  AddBand(&w.mesh, 2, 2 + segments, segments);
  return w;
}

}  // namespace dem_mobility::core
