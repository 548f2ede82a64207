#include "dem_mobility/core/geometry/terrain_mesh.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

using Eigen::Vector2d;
using Eigen::Vector3d;

TerrainMesh::TerrainMesh(TriMesh mesh, double cell, double max_depth)
    : mesh_(std::move(mesh)), cell_(cell), max_depth_(max_depth) {
  DM_THROW_UNLESS(cell > 0 && max_depth > 0, "terrain: cell and max_depth must be positive");
  DM_THROW_UNLESS(!mesh_.faces.empty(), "terrain: the mesh has no triangles");
  Vector2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Vector2d hi = -lo;
  for (const auto& v : mesh_.vertices) {
    lo = lo.cwiseMin(v.head<2>());
    hi = hi.cwiseMax(v.head<2>());
  }
  origin_ = lo;
  nx_ = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)));
  ny_ = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)));
  DM_THROW_UNLESS(static_cast<double>(nx_) * ny_ < 5e7, "terrain: grid of ", nx_, " x ", ny_,
                  " cells is too large; use a larger cell");
  faces_.resize(mesh_.faces.size());
  std::vector<std::vector<int>> bins(static_cast<size_t>(nx_) * ny_);
  cell_zmax_.assign(bins.size(), -std::numeric_limits<double>::infinity());
  for (size_t f = 0; f < mesh_.faces.size(); ++f) {
    const auto& t = mesh_.faces[f];
    for (int i : t) DM_THROW_UNLESS(i >= 0 && i < static_cast<int>(mesh_.vertices.size()),
                                    "terrain: face ", f, " has vertex index ", i, " out of range");
    const Vector3d& p0 = mesh_.vertices[t[0]];
    const Vector3d& p1 = mesh_.vertices[t[1]];
    const Vector3d& p2 = mesh_.vertices[t[2]];
    const Vector3d n = (p1 - p0).cross(p2 - p0);
    DM_THROW_UNLESS(n.norm() > 1e-14, "terrain: face ", f, " is degenerate");
    Face& F = faces_[f];
    F.n = n.normalized();
    DM_THROW_UNLESS(F.n.z() > 0.05, "terrain: face ", f, " does not face up (normal z = ", F.n.z(),
                    "); a terrain surface must be a height field facing +z");
    F.offset = F.n.dot(p0);
    F.o = p0.head<2>();
    Eigen::Matrix2d m;
    m.col(0) = (p1 - p0).head<2>();
    m.col(1) = (p2 - p0).head<2>();
    F.inv = m.inverse();
    const Vector2d flo = p0.head<2>().cwiseMin(p1.head<2>()).cwiseMin(p2.head<2>());
    const Vector2d fhi = p0.head<2>().cwiseMax(p1.head<2>()).cwiseMax(p2.head<2>());
    const double zmax = std::max({p0.z(), p1.z(), p2.z()});
    // a face that only touches a cell's border is not binned there (1e-9 cell inward)
    constexpr double kIn = 1e-9;
    const int ix0 = std::clamp(static_cast<int>(std::floor((flo.x() - origin_.x()) / cell_ + kIn)), 0, nx_ - 1);
    const int ix1 = std::clamp(static_cast<int>(std::floor((fhi.x() - origin_.x()) / cell_ - kIn)), 0, nx_ - 1);
    const int iy0 = std::clamp(static_cast<int>(std::floor((flo.y() - origin_.y()) / cell_ + kIn)), 0, ny_ - 1);
    const int iy1 = std::clamp(static_cast<int>(std::floor((fhi.y() - origin_.y()) / cell_ - kIn)), 0, ny_ - 1);
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        bins[CellIndex(ix, iy)].push_back(static_cast<int>(f));
        cell_zmax_[CellIndex(ix, iy)] = std::max(cell_zmax_[CellIndex(ix, iy)], zmax);
      }
  }
  // cells tiled by coplanar triangles that lie inside them (total area = cell area)
  cell_planar_.assign(bins.size(), 0);
  cell_plane_.assign(bins.size(), Eigen::Vector4d::Zero());
  for (int iy = 0; iy < ny_; ++iy)
    for (int ix = 0; ix < nx_; ++ix) {
      const auto& b = bins[CellIndex(ix, iy)];
      if (b.empty()) continue;
      const Vector2d clo = origin_ + cell_ * Vector2d(ix, iy), chi = clo + Vector2d(cell_, cell_);
      const Face& f0 = faces_[b[0]];
      double area = 0.0;
      bool ok = true;
      for (int f : b) {
        const Face& F = faces_[f];
        ok = ok && (F.n - f0.n).norm() < 1e-12 && std::abs(F.offset - f0.offset) < 1e-12;
        const auto& t = mesh_.faces[f];
        for (int i : t) {
          const Vector2d q = mesh_.vertices[i].head<2>();
          ok = ok && (q.array() >= clo.array() - 1e-9).all() && (q.array() <= chi.array() + 1e-9).all();
        }
        const Vector3d& p0 = mesh_.vertices[t[0]];
        area += 0.5 * std::abs(((mesh_.vertices[t[1]] - p0).head<2>().x() * (mesh_.vertices[t[2]] - p0).head<2>().y() -
                                (mesh_.vertices[t[1]] - p0).head<2>().y() * (mesh_.vertices[t[2]] - p0).head<2>().x()));
      }
      if (ok && std::abs(area - cell_ * cell_) < 1e-9 * cell_ * cell_) {
        cell_planar_[CellIndex(ix, iy)] = 1;
        cell_plane_[CellIndex(ix, iy)] << f0.n, f0.offset;
      }
    }
  cell_start_.resize(bins.size() + 1, 0);
  for (size_t i = 0; i < bins.size(); ++i) cell_start_[i + 1] = cell_start_[i] + static_cast<int>(bins[i].size());
  cell_faces_.reserve(cell_start_.back());
  for (const auto& b : bins) cell_faces_.insert(cell_faces_.end(), b.begin(), b.end());
}

bool TerrainMesh::Query(const Vector3d& p, Hit* hit) const {
  const int ix = static_cast<int>(std::floor((p.x() - origin_.x()) / cell_));
  const int iy = static_cast<int>(std::floor((p.y() - origin_.y()) / cell_));
  if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) return false;
  const int c = CellIndex(ix, iy);
  bool found = false;
  constexpr double kEps = 1e-9;
  for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
    const Face& F = faces_[cell_faces_[k]];
    const double depth = F.offset - F.n.dot(p);
    if (depth <= 0.0 || depth > max_depth_) continue;
    if (found && depth <= hit->depth) continue;
    const Vector2d l = F.inv * (p.head<2>() - F.o);
    if (l.x() < -kEps || l.y() < -kEps || l.x() + l.y() > 1.0 + kEps) continue;
    hit->depth = depth;
    hit->normal = F.n;
    hit->face = cell_faces_[k];
    found = true;
  }
  return found;
}

bool TerrainMesh::BoxPlane(const Vector2d& lo, const Vector2d& hi, Vector3d* n, double* offset) const {
  const int ix0 = static_cast<int>(std::floor((lo.x() - origin_.x()) / cell_));
  const int ix1 = static_cast<int>(std::floor((hi.x() - origin_.x()) / cell_));
  const int iy0 = static_cast<int>(std::floor((lo.y() - origin_.y()) / cell_));
  const int iy1 = static_cast<int>(std::floor((hi.y() - origin_.y()) / cell_));
  if (ix0 < 0 || iy0 < 0 || ix1 >= nx_ || iy1 >= ny_) return false;
  const Eigen::Vector4d& p0 = cell_plane_[CellIndex(ix0, iy0)];
  for (int iy = iy0; iy <= iy1; ++iy)
    for (int ix = ix0; ix <= ix1; ++ix) {
      const int c = CellIndex(ix, iy);
      if (!cell_planar_[c] || (cell_plane_[c] - p0).cwiseAbs().maxCoeff() > 1e-12) return false;
    }
  *n = p0.head<3>();
  *offset = p0(3);
  return true;
}

double TerrainMesh::MaxHeight(const Vector2d& lo, const Vector2d& hi) const {
  const int ix0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin_.x()) / cell_)));
  const int ix1 = std::min(nx_ - 1, static_cast<int>(std::floor((hi.x() - origin_.x()) / cell_)));
  const int iy0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin_.y()) / cell_)));
  const int iy1 = std::min(ny_ - 1, static_cast<int>(std::floor((hi.y() - origin_.y()) / cell_)));
  double z = -std::numeric_limits<double>::infinity();
  for (int iy = iy0; iy <= iy1; ++iy)
    for (int ix = ix0; ix <= ix1; ++ix) z = std::max(z, cell_zmax_[CellIndex(ix, iy)]);
  return z;
}

}  // namespace dem_mobility::core
