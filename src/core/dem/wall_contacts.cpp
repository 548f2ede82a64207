#include "dem_mobility/core/dem/wall_contacts.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

DemWall MakeQuadWall(const std::string& name, const Vector3d& o, const Vector3d& e1, const Vector3d& e2) {
  DemWall w;
  w.name = name;
  w.mesh.vertices = {o, o + e1, o + e1 + e2, o + e2};
  w.mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  return w;
}

int WallContacts::Add(DemWall wall, const SoilParams& soil, int slots) {
  DM_THROW_UNLESS(!wall.mesh.faces.empty(), "wall '", wall.name, "' has no triangles");
  DM_THROW_UNLESS(wall.friction >= 0.0 && wall.adhesion_factor >= 0.0, "wall '", wall.name,
                  "': friction and adhesion_factor must be >= 0");
  SoilParams wp = soil;
  wp.friction = wall.friction;
  law_.emplace_back(wp);
  walls_.push_back(std::move(wall));
  // one contact history per slot and wall (nothing has touched yet: walls come before the build)
  hist_.assign(static_cast<size_t>(slots) * walls_.size(), TangentialHistory());
  touching_.assign(static_cast<size_t>(slots) * walls_.size(), 0);
  return size() - 1;
}

void WallContacts::AppendSlot(bool built) {
  const size_t W = walls_.size();
  hist_.resize(hist_.size() + W);
  touching_.resize(touching_.size() + W, 0);
  if (built) tri_start_.push_back(tri_start_.back());
}

void WallContacts::ClearSlot(int s) {
  const size_t W = walls_.size();
  for (size_t w = 0; w < W; ++w) {
    hist_[s * W + w] = TangentialHistory();
    touching_[s * W + w] = 0;
  }
}

void WallContacts::PermuteSlots(const std::vector<int>& order) {
  core::PermuteSlots(&hist_, order, walls_.size());
  core::PermuteSlots(&touching_, order, walls_.size());
}

void WallContacts::UpdateVertices() {
  vertices_.resize(walls_.size());
  for (size_t w = 0; w < walls_.size(); ++w) {
    const DemWall& wl = walls_[w];
    vertices_[w].resize(wl.mesh.vertices.size());
    for (size_t k = 0; k < wl.mesh.vertices.size(); ++k) vertices_[w][k] = wl.position + wl.rotation * wl.mesh.vertices[k];
  }
}

double WallContacts::MaxWallDisplacement(bool fast) const {
  double m2 = 0.0;
  for (size_t w = 0; w < vertices_.size() && w < built_vertices_.size(); ++w)
    for (size_t k = 0; k < vertices_[w].size() && walls_[w].fast == fast; ++k)
      m2 = std::max(m2, (vertices_[w][k] - built_vertices_[w][k]).squaredNorm());
  return std::sqrt(m2);
}

bool WallContacts::NeedsBuild(double particle_displacement) const {
  if (walls_.empty()) return false;
  // a particle's distance from where it was at the wall build is at most its distance from x_built
  // now plus the largest such distance at the build
  const double margin = cutoff_ - 0.5 * diameter_;
  const double walls = std::max(MaxWallDisplacement(true), MaxWallDisplacement(false));
  return walls + particle_displacement + built_particle_displacement_ > margin;
}

void WallContacts::Build(const ParticleStore& ps, int threads, double particle_displacement) {
  const int n = ps.slots();
  UpdateVertices();
  built_vertices_ = vertices_;
  built_particle_displacement_ = particle_displacement;
  tris_.clear();
  for (int w = 0; w < size(); ++w)
    for (int f = 0; f < static_cast<int>(walls_[w].mesh.faces.size()); ++f) tris_.push_back({w, f});
  // each live slot's candidates: the triangles whose box, grown by the cutoff, holds it
  std::vector<std::vector<int>> cand(n);
  if (!tris_.empty()) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int i = 0; i < n; ++i) {
      if (!ps.live(i)) continue;
      for (int t = 0; t < static_cast<int>(tris_.size()); ++t) {
        const WallTri& tr = tris_[t];
        const auto& face = walls_[tr.wall].mesh.faces[tr.face];
        const std::vector<Vector3d>& wv = vertices_[tr.wall];
        const Vector3d tlo = wv[face[0]].cwiseMin(wv[face[1]]).cwiseMin(wv[face[2]]).array() - cutoff_;
        const Vector3d thi = wv[face[0]].cwiseMax(wv[face[1]]).cwiseMax(wv[face[2]]).array() + cutoff_;
        if ((ps.x[i].array() >= tlo.array()).all() && (ps.x[i].array() <= thi.array()).all()) cand[i].push_back(t);
      }
    }
  }
  tri_start_.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) tri_start_[i + 1] = tri_start_[i] + static_cast<int>(cand[i].size());
  tri_of_slot_.resize(tri_start_[n]);
  for (int i = 0; i < n; ++i) std::copy(cand[i].begin(), cand[i].end(), tri_of_slot_.begin() + tri_start_[i]);
  ++builds_;
}

void WallContacts::ComputeSlot(ParticleStore* ps, int i, double dt, WallSum* sum) {
  // per wall the deepest of the candidate triangles (a particle added since the last neighbour
  // build tries them all); the candidates come in wall order: one pass, a group per wall
  const int W = size();
  const bool fresh = ps->state[i] == SlotState::kAdded;
  const int t_begin = fresh ? 0 : tri_start_[i];
  const int t_end = fresh ? static_cast<int>(tris_.size()) : tri_start_[i + 1];
  if (t_begin == t_end) {  // no wall near: clear what an earlier contact left
    for (int w = 0; w < W; ++w) ClearHistory(static_cast<size_t>(i) * W + w);
    return;
  }
  const double D = diameter_;
  const Vector3d xi = ps->x[i], vi = ps->v[i];
  const double pi = ps->plastic[i], ai = ps->adhesion_max[i];
  Vector3d f = ps->f[i];
  double max_rep = ps->max_repulsion[i], max_ten = ps->max_tension[i], max_overlap = ps->overlap[i];
  auto tri_at = [&](int t) -> const WallTri& { return tris_[fresh ? t : tri_of_slot_[t]]; };
  int t = t_begin;
  for (int w = 0; w < W; ++w) {
    const size_t hw = static_cast<size_t>(i) * W + w;
    if (t == t_end || tri_at(t).wall != w) {  // no triangle of this wall near
      ClearHistory(hw);
      continue;
    }
    const DemWall& wl = walls_[w];
    double best = 0.0;
    Vector3d q_best = Vector3d::Zero();
    for (; t < t_end && tri_at(t).wall == w; ++t) {
      // the triangle where the wall is now (it may have moved since the build)
      const auto& face = wl.mesh.faces[tri_at(t).face];
      const std::vector<Vector3d>& wv = vertices_[w];
      const Vector3d q = ClosestPointOnTriangle(xi, wv[face[0]], wv[face[1]], wv[face[2]]);
      const double overlap = 0.5 * D - (xi - q).norm();
      if (overlap > best) {
        best = overlap;
        q_best = q;
      }
    }
    const double d = best - pi;
    if (!(d > 0.0)) {
      hist_[hw] = TangentialHistory();
      touching_[hw] = 0;
      continue;
    }
    max_overlap = std::max(max_overlap, best);
    const Vector3d r = xi - q_best;
    const Vector3d nrm = r / r.norm();
    const Vector3d vw = wl.velocity + wl.angular_velocity.cross(q_best - wl.position);
    const Vector3d vr = vi - vw;
    const double vn = vr.dot(nrm);
    const SoilContactLaw& wlaw = law_[w];
    const SoilNormalForce fn = wlaw.Normal(d, -vn, wl.adhesion_factor * ai);
    const Vector3d ft = wlaw.Tangential(nrm, vr - vn * nrm, fn.repulsion, dt, &hist_[hw]);
    const Vector3d fc = fn.Total() * nrm + ft;
    f += fc;
    max_rep = std::max(max_rep, fn.repulsion);
    max_ten = std::max(max_ten, -fn.adhesion);
    touching_[hw] = 1;
    sum[w].force -= fc;
    sum[w].moment += (q_best - wl.wrench_point).cross(-fc);
    sum[w].power += fc.dot(vw);  // the wall's work on the particle, per unit time
    ++sum[w].contacts;
  }
  ps->f[i] = f;
  ps->max_repulsion[i] = max_rep;
  ps->max_tension[i] = max_ten;
  ps->overlap[i] = max_overlap;
}

double WallContacts::SumWrenches(int chunks) {
  const int W = size();
  double power = 0.0;
  for (int w = 0; w < W; ++w) {
    DemWall& wl = walls_[w];
    wl.force.setZero();
    wl.moment.setZero();
    wl.contacts = 0;
    for (int c = 0; c < chunks; ++c) {
      const WallSum& cs = chunk_[static_cast<size_t>(c) * W + w];
      wl.force += cs.force;
      wl.moment += cs.moment;
      wl.contacts += cs.contacts;
      power += cs.power;
    }
  }
  return power;
}

double WallContacts::Compute(ParticleStore* ps, double dt, int threads) {
  const int W = size();
  if (W == 0) return 0.0;
  const int n = ps->slots();
  constexpr int kChunk = 4096;
  const int chunks = (n + kChunk - 1) / kChunk;
  chunk_.assign(static_cast<size_t>(chunks) * W, WallSum());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int c = 0; c < chunks; ++c) {
    WallSum* sum = &chunk_[static_cast<size_t>(c) * W];
    for (int i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i)
      if (ps->live(i)) ComputeSlot(ps, i, dt, sum);
  }
  return SumWrenches(chunks);
}

size_t WallContacts::MemoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(hist_) + bytes(touching_) + bytes(tri_start_) + bytes(tri_of_slot_) + bytes(chunk_);
}

}  // namespace dem_mobility::core
