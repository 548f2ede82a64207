#include "dem_mobility/core/dem/wall_contacts.h"
#include "dem_mobility/core/common/state_archive.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/geometry/trimesh.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {
// A vertex of a wall where its pose puts it (the one expression for every wall vertex, so that a
// fast wall's vertices taken in ComputeSlot are those of its build, bit for bit).
inline Vector3d WorldVertex(const DemWall& wl, int k) { return wl.position + wl.rotation * wl.mesh.vertices[k]; }
}  // namespace

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
  DM_THROW_UNLESS(std::isfinite(wall.margin), "wall '", wall.name, "': margin must be finite");
  SoilParams wp = soil;
  wp.friction = wall.friction;
  law_.emplace_back(wp);
  const double margin = wall.margin > 0.0 ? wall.margin : cutoff_ - diameter_;  // (the skin)
  margin_.push_back(margin);
  reach_.push_back(0.5 * diameter_ + margin);
  tri_begin_.push_back(static_cast<int>(tris_.size()));
  double radius = 0.0;
  for (const Vector3d& v : wall.mesh.vertices) radius = std::max(radius, v.norm());
  radius_.push_back(radius);
  const int w = static_cast<int>(walls_.size());
  for (int f = 0; f < static_cast<int>(wall.mesh.faces.size()); ++f) {
    tris_.push_back({w, f});
    const auto& fc = wall.mesh.faces[f];
    const Vector3d a = wall.mesh.vertices[fc[0]], b = wall.mesh.vertices[fc[1]], c = wall.mesh.vertices[fc[2]];
    TriBound tb;
    tb.centroid = (a + b + c) / 3.0;
    const Vector3d nrm = (b - a).cross(c - a);
    tb.normal = nrm.norm() > 0.0 ? Vector3d(nrm / nrm.norm()) : Vector3d::Zero();
    tb.rho = std::max({(a - tb.centroid).norm(), (b - tb.centroid).norm(), (c - tb.centroid).norm()}) * (1.0 + 1e-9);
    tri_bound_.push_back(tb);
  }
  walls_.push_back(std::move(wall));
  bins_.emplace_back();
  if (use_bins_ && static_cast<int>(walls_.back().mesh.faces.size()) >= kBinMinFaces) MakeBins(w);
  // one contact history per slot and wall (nothing has touched yet: walls come before the build)
  hist_.assign(static_cast<size_t>(slots) * walls_.size(), TangentialHistory());
  touching_.assign(static_cast<size_t>(slots) * walls_.size(), 0);
  return size() - 1;
}

int WallContacts::Bins::Cell(const Vector3d& b) const {
  const Vector3d u = (b - lo) / cell;
  if (!(u.x() >= 0.0 && u.y() >= 0.0 && u.z() >= 0.0)) return -1;
  const int ix = static_cast<int>(u.x()), iy = static_cast<int>(u.y()), iz = static_cast<int>(u.z());
  if (ix >= nx || iy >= ny || iz >= nz) return -1;
  return (iz * ny + iy) * nx + ix;
}

void WallContacts::MakeBins(int w) {
  const TriMesh& m = walls_[w].mesh;
  const int F = static_cast<int>(m.faces.size());
  const double reach = reach_[w];
  // a particle within `reach` of a face lies within (largest centroid-vertex distance + reach) of
  // its centroid, in any frame; a little more for the round-off of the world vertices
  std::vector<Vector3d> g(F);
  std::vector<double> rad(F);
  Vector3d lo = Vector3d::Constant(1e300), hi = Vector3d::Constant(-1e300);
  for (int f = 0; f < F; ++f) {
    const auto& fc = m.faces[f];
    g[f] = (m.vertices[fc[0]] + m.vertices[fc[1]] + m.vertices[fc[2]]) / 3.0;
    double rho = 0.0;
    for (int k = 0; k < 3; ++k) rho = std::max(rho, (m.vertices[fc[k]] - g[f]).norm());
    rad[f] = (rho + reach) * (1.0 + 1e-9) + 1e-9;
    lo = lo.cwiseMin((g[f].array() - rad[f]).matrix());
    hi = hi.cwiseMax((g[f].array() + rad[f]).matrix());
  }
  Bins& b = bins_[w];
  b.lo = lo;
  b.cell = reach;
  const Vector3d ext = hi - lo;
  while ((ext / b.cell).array().ceil().prod() > 4.0e6) b.cell *= 1.5;  // at most 4M cells
  b.nx = std::max(1, static_cast<int>(std::ceil(ext.x() / b.cell)));
  b.ny = std::max(1, static_cast<int>(std::ceil(ext.y() / b.cell)));
  b.nz = std::max(1, static_cast<int>(std::ceil(ext.z() / b.cell)));
  const size_t cells = static_cast<size_t>(b.nx) * b.ny * b.nz;
  // two passes (count, fill) in face order: each cell's list comes out in increasing order
  b.start.assign(cells + 1, 0);
  auto each_cell = [&](int f, auto&& visit) {
    const Vector3d a = (g[f].array() - rad[f] - lo.array()) / b.cell, z = (g[f].array() + rad[f] - lo.array()) / b.cell;
    const int x0 = std::max(0, static_cast<int>(std::floor(a.x()))), x1 = std::min(b.nx - 1, static_cast<int>(z.x()));
    const int y0 = std::max(0, static_cast<int>(std::floor(a.y()))), y1 = std::min(b.ny - 1, static_cast<int>(z.y()));
    const int z0 = std::max(0, static_cast<int>(std::floor(a.z()))), z1 = std::min(b.nz - 1, static_cast<int>(z.z()));
    for (int iz = z0; iz <= z1; ++iz)
      for (int iy = y0; iy <= y1; ++iy)
        for (int ix = x0; ix <= x1; ++ix) {
          const Vector3d clo = lo + b.cell * Vector3d(ix, iy, iz);
          const Vector3d d = (clo - g[f]).cwiseMax(g[f] - (clo.array() + b.cell).matrix()).cwiseMax(Vector3d::Zero());
          if (d.squaredNorm() <= rad[f] * rad[f]) visit((iz * b.ny + iy) * b.nx + ix);
        }
  };
  for (int f = 0; f < F; ++f) each_cell(f, [&](int c) { ++b.start[c + 1]; });
  for (size_t c = 0; c < cells; ++c) b.start[c + 1] += b.start[c];
  b.faces.resize(b.start[cells]);
  std::vector<int> fill(b.start.begin(), b.start.end() - 1);
  for (int f = 0; f < F; ++f) each_cell(f, [&](int c) { b.faces[fill[c]++] = f; });
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
  // Only a slot touching a wall has a history that is not zero (a contact's end clears it:
  // ClearHistory; a checkpoint is checked for it, Io). So the slots with a contact are moved out
  // and put back at their new slots, and the rest of the two arrays, zero, stays where it is: no
  // pass over all of hist_ (slots x walls x 24 B, 181 MB at the paper level, at every build; a
  // gather into a new array had the kernel zero that many fresh pages each time), and nothing
  // allocated once the scratch has grown.
  const size_t W = walls_.size();
  if (W == 0) return;
  const size_t n = touching_.size() / W;
  moved_slot_.clear();
  moved_hist_.clear();
  moved_touching_.clear();
  for (size_t o = 0; o < n; ++o) {
    unsigned char* t = &touching_[o * W];
    unsigned char any = 0;
    for (size_t w = 0; w < W; ++w) any |= t[w];
    if (!any) continue;
    moved_slot_.push_back(static_cast<int>(o));
    for (size_t w = 0; w < W; ++w) {
      moved_touching_.push_back(t[w]);
      if (!t[w]) continue;  // (its history is zero: only the walls it touches are read)
      moved_hist_.push_back(hist_[o * W + w]);
      t[w] = 0;
      hist_[o * W + w] = TangentialHistory();
    }
  }
  // each old slot's new one (the slots beyond the permutation's stay)
  new_slot_.resize(n);
  for (size_t s = 0; s < n; ++s) new_slot_[s] = static_cast<int>(s);
  for (size_t s = 0; s < order.size(); ++s) new_slot_[order[s]] = static_cast<int>(s);
  const TangentialHistory* h = moved_hist_.data();
  for (size_t k = 0; k < moved_slot_.size(); ++k) {
    const size_t s = static_cast<size_t>(new_slot_[moved_slot_[k]]);
    for (size_t w = 0; w < W; ++w)
      if (moved_touching_[k * W + w]) {
        touching_[s * W + w] = moved_touching_[k * W + w];
        hist_[s * W + w] = *h++;
      }
  }
}

void WallContacts::UpdateVertices(bool all) {
  vertices_.resize(walls_.size());
  for (size_t w = 0; w < walls_.size(); ++w) {
    const DemWall& wl = walls_[w];
    if (wl.fast && !all) continue;  // (taken where a contact needs them: ComputeSlot)
    std::vector<Vector3d>& now = vertices_[w];
    now.resize(wl.mesh.vertices.size());
    for (size_t k = 0; k < now.size(); ++k) now[k] = WorldVertex(wl, static_cast<int>(k));
  }
  Displacements();
}

double WallContacts::FastDisplacement(int w) const {
  if (w >= static_cast<int>(built_position_.size())) return 0.0;  // (not built yet)
  const DemWall& wl = walls_[w];
  const double moved =
      (wl.position - built_position_[w]).norm() + (wl.rotation - built_rotation_[w]).norm() * radius_[w];
  // (a vertex is where p + R v rounds to: far less than 1e-12 of |p| + |v| from it)
  return moved + 1e-12 * (wl.position.norm() + built_position_[w].norm() + radius_[w]);
}

void WallContacts::Displacements() {
  displacement_.assign(walls_.size(), 0.0);
  for (size_t w = 0; w < walls_.size(); ++w) {
    if (walls_[w].fast) {
      displacement_[w] = FastDisplacement(static_cast<int>(w));
      continue;
    }
    if (w >= vertices_.size() || w >= built_vertices_.size() || built_vertices_[w].size() != vertices_[w].size())
      continue;  // (not built yet)
    double m2 = 0.0;
    for (size_t k = 0; k < vertices_[w].size(); ++k)
      m2 = std::max(m2, (vertices_[w][k] - built_vertices_[w][k]).squaredNorm());
    displacement_[w] = std::sqrt(m2);
  }
}

double WallContacts::WallDisplacement(int w) const {
  return w < static_cast<int>(displacement_.size()) ? displacement_[w] : 0.0;
}

double WallContacts::MaxWallDisplacement(bool fast) const {
  double m = 0.0;
  for (int w = 0; w < size(); ++w)
    if (walls_[w].fast == fast) m = std::max(m, WallDisplacement(w));
  return m;
}

bool WallContacts::NeedsBuild(double particle_displacement) const {
  // a particle's distance from where it was at the wall build is at most its distance from x_built
  // now plus the largest such distance at the build
  const double particles = particle_displacement + built_particle_displacement_;
  for (int w = 0; w < size(); ++w)
    if (WallDisplacement(w) + particles > margin_[w]) return true;
  return false;
}

bool WallContacts::Near(const Vector3d& x, int t) const {
  if (!((x.array() >= tri_lo_[t].array()).all() && (x.array() <= tri_hi_[t].array()).all())) return false;
  const WallTri& tr = tris_[t];
  const auto& face = walls_[tr.wall].mesh.faces[tr.face];
  const std::vector<Vector3d>& wv = vertices_[tr.wall];
  const double r = reach_[tr.wall];
  return (x - ClosestPointOnTriangle(x, wv[face[0]], wv[face[1]], wv[face[2]])).squaredNorm() <= r * r;
}

void WallContacts::SlotCandidates(const Vector3d& x, std::vector<int>* out) const {
  for (int w = 0; w < size(); ++w) {
    // outside the box of the wall's triangles' boxes no triangle is near (a tire above the soil,
    // a wall at the other end of the bin): passed by before its bins or its triangles
    if (!((x.array() >= wall_lo_[w].array()).all() && (x.array() <= wall_hi_[w].array()).all())) continue;
    const Bins& b = bins_[w];
    if (b.start.empty()) {
      const int end = w + 1 < size() ? tri_begin_[w + 1] : static_cast<int>(tris_.size());
      for (int t = tri_begin_[w]; t < end; ++t)
        if (Near(x, t)) out->push_back(t);
      continue;
    }
    const DemWall& wl = walls_[w];
    const int c = b.Cell(wl.rotation.transpose() * (x - wl.position));
    if (c < 0) continue;
    for (int k = b.start[c]; k < b.start[c + 1]; ++k)
      if (Near(x, tri_begin_[w] + b.faces[k])) out->push_back(tri_begin_[w] + b.faces[k]);
  }
}

void WallContacts::Build(const ParticleStore& ps, int threads, double particle_displacement) {
  const int n = ps.slots();
  UpdateVertices(true);
  // where the walls are at the build: a slow wall's vertices, a fast wall's pose (FastDisplacement)
  built_vertices_.resize(walls_.size());
  built_position_.resize(walls_.size());
  built_rotation_.resize(walls_.size());
  for (size_t w = 0; w < walls_.size(); ++w) {
    if (walls_[w].fast)
      built_vertices_[w].clear();
    else
      built_vertices_[w].assign(vertices_[w].begin(), vertices_[w].end());
    built_position_[w] = walls_[w].position;
    built_rotation_[w] = walls_[w].rotation;
  }
  displacement_.assign(walls_.size(), 0.0);
  built_particle_displacement_ = particle_displacement;
  // each triangle's world box, grown by its wall's reach: the cheap test before the distance
  const int T = static_cast<int>(tris_.size());
  tri_lo_.resize(T);
  tri_hi_.resize(T);
  for (int t = 0; t < T; ++t) {
    const WallTri& tr = tris_[t];
    const auto& face = walls_[tr.wall].mesh.faces[tr.face];
    const std::vector<Vector3d>& wv = vertices_[tr.wall];
    tri_lo_[t] = wv[face[0]].cwiseMin(wv[face[1]]).cwiseMin(wv[face[2]]).array() - reach_[tr.wall];
    tri_hi_[t] = wv[face[0]].cwiseMax(wv[face[1]]).cwiseMax(wv[face[2]]).array() + reach_[tr.wall];
  }
  wall_lo_.assign(walls_.size(), Vector3d::Constant(std::numeric_limits<double>::infinity()));
  wall_hi_.assign(walls_.size(), Vector3d::Constant(-std::numeric_limits<double>::infinity()));
  for (int t = 0; t < T; ++t) {
    const int w = tris_[t].wall;
    wall_lo_[w] = wall_lo_[w].cwiseMin(tri_lo_[t]);
    wall_hi_[w] = wall_hi_[w].cwiseMax(tri_hi_[t]);
  }
  // each live slot's candidates, chunk by chunk of slots (in slot order within a chunk), then the
  // chunks joined in order: the same lists for any thread count
  constexpr int kChunk = 4096;
  const int chunks = (n + kChunk - 1) / kChunk;
  if (static_cast<int>(chunk_tris_.size()) < chunks) chunk_tris_.resize(chunks);
  count_.assign(n, 0);
  if (T > 0) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int c = 0; c < chunks; ++c) {
      std::vector<int>& out = chunk_tris_[c];
      out.clear();
      for (int i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
        if (!ps.live(i)) continue;
        const size_t before = out.size();
        SlotCandidates(ps.x[i], &out);
        count_[i] = static_cast<int>(out.size() - before);
      }
    }
  }
  tri_start_.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) tri_start_[i + 1] = tri_start_[i] + count_[i];
  // a listed slot with no triangle near keeps no wall contact until the next build: its histories
  // are cleared here, once, and Compute passes it by (before, it cleared them at every step); a
  // slot added since the neighbour build finds its triangles itself at every step (ComputeSlot)
  const int W = size();
  for (int i = 0; i < n; ++i)
    if (count_[i] == 0 && ps.state[i] != SlotState::kAdded)
      for (int w = 0; w < W; ++w) ClearHistory(static_cast<size_t>(i) * W + w);
  tri_of_slot_.resize(tri_start_[n]);
  if (T > 0)
    for (int c = 0; c < chunks; ++c)
      std::copy(chunk_tris_[c].begin(), chunk_tris_[c].end(), tri_of_slot_.begin() + tri_start_[c * kChunk]);
  ++builds_;
}

void WallContacts::ComputeSlot(ParticleStore* ps, int i, double dt, WallSum* sum) {
  // per wall the deepest of the candidate triangles (a particle added since the last neighbour
  // build tries them all); the candidates come in wall order: one pass, a group per wall
  const int W = size();
  const bool fresh = ps->state[i] == SlotState::kAdded;
  // a particle added since the build: every triangle near it now (its cell's, on a binned wall)
  thread_local std::vector<int> fresh_tris;
  if (fresh) {
    fresh_tris.clear();
    for (int w = 0; w < W; ++w) {
      const Bins& b = bins_[w];
      const int end = w + 1 < W ? tri_begin_[w + 1] : static_cast<int>(tris_.size());
      if (b.start.empty()) {
        for (int t = tri_begin_[w]; t < end; ++t) fresh_tris.push_back(t);
        continue;
      }
      const DemWall& wl = walls_[w];
      const int c = b.Cell(wl.rotation.transpose() * (ps->x[i] - wl.position));
      if (c >= 0)
        for (int k = b.start[c]; k < b.start[c + 1]; ++k) fresh_tris.push_back(tri_begin_[w] + b.faces[k]);
    }
  }
  const int t_begin = fresh ? 0 : tri_start_[i];
  const int t_end = fresh ? static_cast<int>(fresh_tris.size()) : tri_start_[i + 1];
  if (t_begin == t_end) {  // no wall near: clear what an earlier contact left
    for (int w = 0; w < W; ++w) ClearHistory(static_cast<size_t>(i) * W + w);
    return;
  }
  const double D = diameter_;
  const Vector3d xi = ps->x[i], vi = ps->v[i];
  const double pi = ps->plastic[i], ai = ps->adhesion_max[i];
  PairSums& si = ps->sums[i];
  Vector3d f(si.f[0], si.f[1], si.f[2]);
  double max_rep = si.max_repulsion, normal_sum = si.normal_sum, reach_sum = si.adhesion_reach;
  double contacts = si.contacts, max_overlap = si.overlap;
  auto tri_at = [&](int t) -> const WallTri& { return tris_[fresh ? fresh_tris[t] : tri_of_slot_[t]]; };
  // the walls with no triangle near (most of them: a particle is near one wall or two) only clear
  // what an earlier contact left, walls [w0, w1) at once
  const size_t base = static_cast<size_t>(i) * W;
  auto clear = [&](int w0, int w1) {
    unsigned char any = 0;  // (a look at the flags first: mostly none is set)
    for (int w = w0; w < w1; ++w) any |= touching_[base + w];
    if (any)
      for (int w = w0; w < w1; ++w) ClearHistory(base + w);
  };
  int t = t_begin, cleared = 0;
  while (t < t_end) {
    const int w = tri_at(t).wall;
    clear(cleared, w);
    cleared = w + 1;
    const size_t hw = base + w;
    const DemWall& wl = walls_[w];
    // the deepest candidate's overlap (0 while none overlaps) and its squared distance
    double best = 0.0, best_d2 = std::numeric_limits<double>::infinity();
    Vector3d q_best = Vector3d::Zero();
    // on a binned wall, the particle in the body frame: a candidate that cannot be nearer than
    // 0.5 D - best (plus `slack`, far beyond the round-off of the frames) is passed by
    const bool bounded = !bins_[w].start.empty();
    const Vector3d xb = bounded ? Vector3d(wl.rotation.transpose() * (xi - wl.position)) : Vector3d::Zero();
    const double slack = 1e-9 * D;
    for (; t < t_end && tri_at(t).wall == w; ++t) {
      const int tt = fresh ? fresh_tris[t] : tri_of_slot_[t];
      if (bounded) {
        // passed by where l >= rho + s, s = sqrt(reach^2 - h^2) (TriBound), squared twice so
        // that no root is taken: l^2 - rho^2 - s^2 >= 2 rho s
        const TriBound& b = tri_bound_[tt];
        const double reach = 0.5 * D - best + slack;
        const Vector3d e = xb - b.centroid;
        const double h = b.normal.dot(e);
        if (std::abs(h) >= reach) continue;
        const double s2 = reach * reach - h * h;
        const double a = (e.squaredNorm() - h * h) - b.rho * b.rho - s2;
        if (a >= 0.0 && a * a >= 4.0 * b.rho * b.rho * s2) continue;
      }
      // the triangle where the wall is now (it may have moved since the build; a fast wall's
      // vertices are taken here, as UpdateVertices takes a slow one's)
      const auto& face = wl.mesh.faces[tris_[tt].face];
      Vector3d q;
      if (wl.fast) {
        q = ClosestPointOnTriangle(xi, WorldVertex(wl, face[0]), WorldVertex(wl, face[1]), WorldVertex(wl, face[2]));
      } else {
        const std::vector<Vector3d>& wv = vertices_[w];
        q = ClosestPointOnTriangle(xi, wv[face[0]], wv[face[1]], wv[face[2]]);
      }
      // deeper than the deepest so far only if nearer than it: the root only then (a candidate
      // as deep as it is passed by, as before: the first of the deepest stays)
      const double d2 = (xi - q).squaredNorm();
      if (d2 < best_d2) {
        const double overlap = 0.5 * D - std::sqrt(d2);
        if (overlap > best) {
          best = overlap;
          best_d2 = d2;
          q_best = q;
        }
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
    // the plastic drive (PlasticDrive): a wall's adhesion is its factor times the particle's own
    max_rep = std::max(max_rep, fn.repulsion);
    normal_sum += fn.adhesion + fn.repulsion;
    if (wlaw.cohesion)
      reach_sum += wl.adhesion_factor * AdhesionReach(wlaw.d0, wlaw.dp, wlaw.inv_dp, wlaw.inv_d0_dp, d);
    // (a wall adhering more strongly than a particle counts as that many contacts in the bound)
    contacts += std::max(1.0, wl.adhesion_factor);
    touching_[hw] = 1;
    sum[w].force -= fc;
    sum[w].moment += (q_best - wl.wrench_point).cross(-fc);
    sum[w].power += fc.dot(vw);  // the wall's work on the particle, per unit time
    sum[w].normal += fn.Total();
    ++sum[w].contacts;
  }
  clear(cleared, W);
  si.f[0] = f.x();
  si.f[1] = f.y();
  si.f[2] = f.z();
  si.max_repulsion = max_rep;
  si.normal_sum = normal_sum;
  si.adhesion_reach = reach_sum;
  si.contacts = contacts;
  si.overlap = max_overlap;
}

double WallContacts::SumWrenches(int chunks) {
  const int W = size();
  double power = 0.0;
  for (int w = 0; w < W; ++w) {
    DemWall& wl = walls_[w];
    wl.force.setZero();
    wl.moment.setZero();
    wl.contacts = 0;
    wl.normal_force = 0.0;
    for (int c = 0; c < chunks; ++c) {
      const WallSum& cs = chunk_[static_cast<size_t>(c) * W + w];
      wl.force += cs.force;
      wl.moment += cs.moment;
      wl.contacts += cs.contacts;
      wl.normal_force += cs.normal;
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
      if (ps->live(i) && (ps->state[i] == SlotState::kAdded || tri_start_[i + 1] > tri_start_[i]))
        ComputeSlot(ps, i, dt, sum);
  }
  return SumWrenches(chunks);
}

size_t WallContacts::MemoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  size_t b = bytes(hist_) + bytes(touching_) + bytes(tri_start_) + bytes(tri_of_slot_) + bytes(chunk_) +
             bytes(tri_lo_) + bytes(tri_hi_) + bytes(wall_lo_) + bytes(wall_hi_) + bytes(count_) + bytes(tris_) +
             bytes(tri_bound_) + bytes(displacement_) + bytes(radius_) + bytes(built_position_) +
             bytes(built_rotation_);
  for (const Bins& bn : bins_) b += bytes(bn.start) + bytes(bn.faces);
  for (const std::vector<int>& c : chunk_tris_) b += bytes(c);
  b += bytes(moved_slot_) + bytes(moved_hist_) + bytes(moved_touching_) + bytes(new_slot_);
  return b;
}

template <class Ar>
void WallContacts::Io(Ar& ar) {
  ar.Tag("walls");
  ar.Same(static_cast<long>(walls_.size()), "walls");
  for (DemWall& w : walls_) {
    ar.Tag(w.name.c_str());
    ar.Same(static_cast<long>(w.mesh.vertices.size()), "the wall's vertices");
    ar.Same(static_cast<long>(w.mesh.faces.size()), "the wall's triangles");
    ar(w.position, w.rotation, w.velocity, w.angular_velocity, w.friction, w.adhesion_factor, w.wrench_point, w.force,
       w.moment, w.normal_force, w.contacts);
  }
  ar.Tag("wall_candidates");
  ar(builds_, tri_lo_, tri_hi_, chunk_tris_, count_, vertices_, built_vertices_, built_position_, built_rotation_,
     built_particle_displacement_,
     tri_start_, tri_of_slot_, hist_, touching_, chunk_);
  if constexpr (Ar::kLoading) {
    if (hist_.size() != touching_.size()) ar.Fail("the wall histories differ in length");
    if (vertices_.size() != walls_.size() || (!built_vertices_.empty() && built_vertices_.size() != walls_.size()))
      ar.Fail("the walls' vertices do not match the walls");
    for (size_t w = 0; w < vertices_.size(); ++w)
      if (vertices_[w].size() != walls_[w].mesh.vertices.size()) ar.Fail("a wall's vertices do not match its mesh");
    for (size_t w = 0; w < built_vertices_.size(); ++w)
      if (built_vertices_[w].size() != (walls_[w].fast ? 0 : walls_[w].mesh.vertices.size()))
        ar.Fail("a wall's vertices at its build do not match its mesh");
    if ((!built_position_.empty() && built_position_.size() != walls_.size()) ||
        built_rotation_.size() != built_position_.size())
      ar.Fail("the walls' poses at their build do not match the walls");
    const int T = static_cast<int>(tris_.size());
    for (int t : tri_of_slot_)
      if (t < 0 || t >= T) ar.Fail("a candidate triangle lies beyond the walls'");
    for (const auto& chunk : chunk_tris_)
      for (int t : chunk)
        if (t < 0 || t >= T) ar.Fail("a candidate triangle lies beyond the walls'");
    if (!tri_lo_.empty() && (tri_lo_.size() != tris_.size() || tri_hi_.size() != tris_.size()))
      ar.Fail("the triangles' boxes do not match the triangles");
    if (!walls_.empty() && hist_.size() % walls_.size() != 0) ar.Fail("the wall histories do not match the walls");
    for (size_t k = 0; k < hist_.size(); ++k)
      if (!touching_[k] && !(hist_[k].spring.array() == 0.0).all())
        ar.Fail("a wall history without its contact (the history of a wall the particle does not touch is zero)");
    for (size_t s = 0; s < tri_start_.size(); ++s)
      if (tri_start_[s] < 0 || tri_start_[s] > static_cast<int>(tri_of_slot_.size()) ||
          (s > 0 && tri_start_[s] < tri_start_[s - 1]))
        ar.Fail("a slot's candidates lie beyond the candidates");
    Displacements();
  }
}
template void WallContacts::Io(StateWriter&);
template void WallContacts::Io(StateReader&);

}  // namespace dem_mobility::core
