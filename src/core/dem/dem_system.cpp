#include "dem_mobility/core/dem/dem_system.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/multibody/elements.h"

namespace dem_mobility {

using Eigen::Vector3d;

namespace {
// closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5)
Vector3d ClosestPointOnTriangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}
}  // namespace

DemSystem::DemSystem(const SoilParams& soil, const DemSettings& settings)
    : soil_(soil), settings_(settings), law_(soil) {
  DM_THROW_UNLESS(settings.skin > 0.0 && settings.skin <= 1.0, "DEM skin ", settings.skin,
                  " (fraction of the diameter) must lie in (0, 1]");
  DM_THROW_UNLESS(settings.threads >= 1, "DEM threads ", settings.threads, " must be >= 1");
  DM_THROW_UNLESS(settings.max_overlap > 0.0 && settings.max_overlap < 1.0, "DEM max_overlap ",
                  settings.max_overlap, " must lie in (0, 1)");
  mass_ = soil.Mass();
  cutoff_ = soil.diameter * (1.0 + settings.skin);
}

int DemSystem::AddParticle(const Vector3d& x, const Vector3d& v) {
  DM_THROW_UNLESS(x.allFinite() && v.allFinite(), "particle ", x_.size(), ": position and velocity must be finite");
  x_.push_back(x);
  v_.push_back(v);
  f_.push_back(mass_ * gravity_);
  x_built_.push_back(x);
  plastic_.push_back(0.0);
  adhesion_max_.push_back(MaxAdhesionForce(soil_, 0.0));
  max_repulsion_.push_back(0.0);
  overlap_.push_back(0.0);
  rebuild_ = true;
  return static_cast<int>(x_.size()) - 1;
}

DemWall MakeQuadWall(const std::string& name, const Vector3d& o, const Vector3d& e1, const Vector3d& e2) {
  DemWall w;
  w.name = name;
  w.mesh.vertices = {o, o + e1, o + e1 + e2, o + e2};
  w.mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  return w;
}

int DemSystem::AddWall(DemWall wall) {
  DM_THROW_UNLESS(!finalized_, "wall '", wall.name, "': walls are added before Finalize()");
  DM_THROW_UNLESS(!wall.mesh.faces.empty(), "wall '", wall.name, "' has no triangles");
  DM_THROW_UNLESS(wall.friction >= 0.0 && wall.adhesion_factor >= 0.0, "wall '", wall.name,
                  "': friction and adhesion_factor must be >= 0");
  SoilParams wp = soil_;
  wp.friction = wall.friction;
  wall_law_.emplace_back(wp);
  walls_.push_back(std::move(wall));
  rebuild_ = true;
  return static_cast<int>(walls_.size()) - 1;
}

void DemSystem::UpdateWallVertices() {
  wall_vertices_.resize(walls_.size());
  for (size_t w = 0; w < walls_.size(); ++w) {
    const DemWall& wl = walls_[w];
    wall_vertices_[w].resize(wl.mesh.vertices.size());
    for (size_t k = 0; k < wl.mesh.vertices.size(); ++k)
      wall_vertices_[w][k] = wl.position + wl.rotation * wl.mesh.vertices[k];
  }
}

double DemSystem::MaxWallDisplacement() const {
  double m2 = 0.0;
  for (size_t w = 0; w < wall_vertices_.size() && w < wall_built_vertices_.size(); ++w)
    for (size_t k = 0; k < wall_vertices_[w].size(); ++k)
      m2 = std::max(m2, (wall_vertices_[w][k] - wall_built_vertices_[w][k]).squaredNorm());
  return std::sqrt(m2);
}

DemStepLimit DemSystem::CriticalTimeStep() const {
  // the stiffest branch (repulsion k_n or the anchor spring k_t; the adhesion ramp f_max / peak
  // where it is stiffer) acting from every neighbour at once on one particle
  const double z = settings_.max_coordination;
  double k = std::max(soil_.NormalStiffness(), soil_.TangentialStiffness());
  std::string branch = soil_.NormalStiffness() >= soil_.TangentialStiffness() ? "repulsion" : "tangential spring";
  if (soil_.cohesion && soil_.adhesion_peak > 0.0) {
    double s_max = 0.0;
    for (double s : soil_.adhesion_stress_vs_plastic_strain.y()) s_max = std::max(s_max, s);
    const double k_adh = soil_.cohesion_factor * s_max * soil_.Area() / (soil_.adhesion_peak * soil_.diameter);
    if (k_adh > k) {
      k = k_adh;
      branch = "adhesion ramp";
    }
  }
  const double omega = std::sqrt(z * k / mass_);
  const double zeta = z * soil_.NormalDamping() / (2.0 * std::sqrt(z * k * mass_));
  DemStepLimit lim;
  lim.dt_crit = CriticalStep(omega, zeta);
  lim.detail = detail::Concat(branch, " stiffness ", k, " N/m from ", settings_.max_coordination,
                              " neighbours on a particle of ", mass_, " kg (damping ratio ", zeta, ")");
  return lim;
}

void DemSystem::Finalize(double dt) {
  const DemStepLimit lim = CriticalTimeStep();
  DM_THROW_UNLESS(std::isfinite(dt) && dt > 0.0, "DEM time step ", dt, " s must be positive");
  DM_THROW_UNLESS(dt <= lim.dt_crit, "DEM time step ", dt, " s is above the critical step ", lim.dt_crit, " s (",
                  lim.detail, "); use dt <= ", lim.dt_crit, " s");
  dt_ = dt;
  finalized_ = true;
  BuildNeighbours();
  ComputeForces();
}

void DemSystem::BuildNeighbours() {
  const int n = size();
  // a uniform grid of cells one cutoff wide over the particles' bounding box
  Vector3d lo = Vector3d::Constant(1e300), hi = -lo;
  for (const Vector3d& x : x_) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  if (n == 0) lo = hi = Vector3d::Zero();
  Eigen::Vector3i dims;
  for (int a = 0; a < 3; ++a) dims[a] = std::max(1, static_cast<int>((hi[a] - lo[a]) / cutoff_) + 1);
  const long ncell = static_cast<long>(dims.x()) * dims.y() * dims.z();
  auto cell_of = [&](const Vector3d& x) {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::min(dims[a] - 1, static_cast<int>((x[a] - lo[a]) / cutoff_));
    return c;
  };
  std::vector<int> cell_start(ncell + 1, 0), cell_particles(n), pc(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i c = cell_of(x_[i]);
    pc[i] = (c.z() * dims.y() + c.y()) * dims.x() + c.x();
    ++cell_start[pc[i] + 1];
  }
  for (long c = 0; c < ncell; ++c) cell_start[c + 1] += cell_start[c];
  {
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (int i = 0; i < n; ++i) cell_particles[fill[pc[i]]++] = i;  // ascending index within a cell
  }
  // each particle's neighbours within the cutoff, ascending, in two passes (count, fill)
  const double cut2 = cutoff_ * cutoff_;
  std::vector<std::vector<int>> found(n);
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i c = cell_of(x_[i]);
    std::vector<int>& out = found[i];
    out.clear();
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = c.x() + dx, cy = c.y() + dy, cz = c.z() + dz;
          if (cx < 0 || cy < 0 || cz < 0 || cx >= dims.x() || cy >= dims.y() || cz >= dims.z()) continue;
          const long cell = (static_cast<long>(cz) * dims.y() + cy) * dims.x() + cx;
          for (int k = cell_start[cell]; k < cell_start[cell + 1]; ++k) {
            const int j = cell_particles[k];
            if (j > i && (x_[i] - x_[j]).squaredNorm() < cut2) out.push_back(j);  // half list
          }
        }
    std::sort(out.begin(), out.end());
  }
  std::vector<int> start(n + 1, 0);
  for (int i = 0; i < n; ++i) start[i + 1] = start[i] + static_cast<int>(found[i].size());
  std::vector<int> nbr(start[n]);
  std::vector<TangentialHistory> hist(start[n]);
  std::vector<unsigned char> touching(start[n], 0);
  const int old_n = static_cast<int>(nbr_start_.size()) - 1;
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    // carry each surviving contact's history over (both lists ascending: a merge)
    int o = i < old_n ? nbr_start_[i] : 0;
    const int o_end = i < old_n ? nbr_start_[i + 1] : 0;
    for (int k = start[i], m = 0; k < start[i + 1]; ++k, ++m) {
      const int j = found[i][m];
      nbr[k] = j;
      while (o < o_end && nbr_[o] < j) ++o;
      if (o < o_end && nbr_[o] == j) {
        hist[k] = hist_[o];
        touching[k] = touching_[o];
      }
    }
    x_built_[i] = x_[i];
  }
  nbr_start_.swap(start);
  nbr_.swap(nbr);
  hist_.swap(hist);
  touching_.swap(touching);
  pair_force_.assign(nbr_.size(), Vector3d::Zero());
  pair_rep_.assign(nbr_.size(), 0.0);
  pair_overlap_.assign(nbr_.size(), 0.0);
  // the reverse list: for each particle the pairs in which it is the second, ascending
  rev_start_.assign(n + 1, 0);
  for (int j : nbr_) ++rev_start_[j + 1];
  for (int i = 0; i < n; ++i) rev_start_[i + 1] += rev_start_[i];
  rev_.resize(nbr_.size());
  {
    std::vector<int> fill(rev_start_.begin(), rev_start_.end() - 1);
    for (int k = 0; k < static_cast<int>(nbr_.size()); ++k) rev_[fill[nbr_[k]]++] = k;
  }

  // walls: each particle's candidate triangles, those whose box (grown by the cutoff) holds it
  const int W = num_walls();
  UpdateWallVertices();
  wall_tris_.clear();
  wall_built_vertices_ = wall_vertices_;
  for (int w = 0; w < W; ++w)
    for (int f = 0; f < static_cast<int>(walls_[w].mesh.faces.size()); ++f) wall_tris_.push_back({w, f});
  std::vector<std::vector<int>> cand(n);
  if (!wall_tris_.empty()) {
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
    for (int i = 0; i < n; ++i)
      for (int t = 0; t < static_cast<int>(wall_tris_.size()); ++t) {
        const WallTri& tr = wall_tris_[t];
        const auto& face = walls_[tr.wall].mesh.faces[tr.face];
        const std::vector<Vector3d>& wv = wall_vertices_[tr.wall];
        const Vector3d lo = wv[face[0]].cwiseMin(wv[face[1]]).cwiseMin(wv[face[2]]).array() - cutoff_;
        const Vector3d hi = wv[face[0]].cwiseMax(wv[face[1]]).cwiseMax(wv[face[2]]).array() + cutoff_;
        if ((x_[i].array() >= lo.array()).all() && (x_[i].array() <= hi.array()).all()) cand[i].push_back(t);
      }
  }
  particle_tri_start_.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) particle_tri_start_[i + 1] = particle_tri_start_[i] + static_cast<int>(cand[i].size());
  particle_tris_.resize(particle_tri_start_[n]);
  for (int i = 0; i < n; ++i) std::copy(cand[i].begin(), cand[i].end(), particle_tris_.begin() + particle_tri_start_[i]);
  if (static_cast<int>(wall_hist_.size()) != n * W) {
    wall_hist_.resize(static_cast<size_t>(n) * W);
    wall_touching_.resize(static_cast<size_t>(n) * W, 0);
  }
  wall_force_.assign(static_cast<size_t>(n) * W, Vector3d::Zero());
  wall_moment_.assign(static_cast<size_t>(n) * W, Vector3d::Zero());
  rebuild_ = false;
  ++builds_;
}

void DemSystem::ComputeForces() {
  const int n = size();
  const double D = soil_.diameter, D2 = D * D, dt = dt_;
  const Vector3d weight = mass_ * gravity_;
  // each pair once (half list): its force on the first particle, its repulsion and overlap
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_[k];
      const Vector3d r = x_[i] - x_[j];
      const double r2 = r.squaredNorm();
      if (r2 >= D2) {  // in the skin, not touching
        if (touching_[k]) {
          hist_[k] = TangentialHistory();
          touching_[k] = 0;
          pair_force_[k].setZero();
          pair_rep_[k] = 0.0;
        }
        if (pair_overlap_[k] != 0.0) pair_overlap_[k] = 0.0;
        continue;
      }
      const double dist = std::sqrt(r2);
      pair_overlap_[k] = D - dist;
      // effective penetration: the overlap less both particles' plastic deformation
      const double d = (D - dist) - (plastic_[i] + plastic_[j]);
      if (!(d > 0.0) || dist <= 0.0) {
        if (touching_[k]) {
          hist_[k] = TangentialHistory();
          touching_[k] = 0;
        }
        pair_force_[k].setZero();
        pair_rep_[k] = 0.0;
        continue;
      }
      const Vector3d nrm = r * (1.0 / dist);  // from j toward i
      const Vector3d vr = v_[i] - v_[j];
      const double vn = vr.dot(nrm);
      const SoilNormalForce fn = law_.Normal(d, -vn, std::min(adhesion_max_[i], adhesion_max_[j]));
      const Vector3d vt = vr - vn * nrm;
      const Vector3d ft = law_.Tangential(nrm, vt, fn.repulsion, dt, &hist_[k]);
      pair_force_[k] = fn.Total() * nrm + ft;
      pair_rep_[k] = fn.repulsion;
      touching_[k] = 1;
    }
  }
  // every particle gathers its pairs in a fixed order (its own, then those it is second in):
  // equal and opposite, and the same sums for any thread count
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    Vector3d f = weight;
    double max_rep = 0.0, max_overlap = 0.0;
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      f += pair_force_[k];
      max_rep = std::max(max_rep, pair_rep_[k]);
      max_overlap = std::max(max_overlap, pair_overlap_[k]);
    }
    for (int m = rev_start_[i]; m < rev_start_[i + 1]; ++m) {
      const int k = rev_[m];
      f -= pair_force_[k];
      max_rep = std::max(max_rep, pair_rep_[k]);
      max_overlap = std::max(max_overlap, pair_overlap_[k]);
    }
    // walls: per wall the deepest of the candidate triangles
    const int W = static_cast<int>(walls_.size());
    for (int w = 0; w < W; ++w) {
      wall_force_[static_cast<size_t>(i) * W + w].setZero();
      wall_moment_[static_cast<size_t>(i) * W + w].setZero();
    }
    for (int w = 0; w < W; ++w) {
      const DemWall& wl = walls_[w];
      double best = 0.0;
      Vector3d q_best = Vector3d::Zero();
      for (int k = particle_tri_start_[i]; k < particle_tri_start_[i + 1]; ++k) {
        const WallTri& tr = wall_tris_[particle_tris_[k]];
        if (tr.wall != w) continue;
        // the triangle where the wall is now (it may have moved since the build)
        const auto& face = wl.mesh.faces[tr.face];
        const std::vector<Vector3d>& wv = wall_vertices_[w];
        const Vector3d q = ClosestPointOnTriangle(x_[i], wv[face[0]], wv[face[1]], wv[face[2]]);
        const double overlap = 0.5 * D - (x_[i] - q).norm();
        if (overlap > best) {
          best = overlap;
          q_best = q;
        }
      }
      const size_t hw = static_cast<size_t>(i) * W + w;
      const double d = best - plastic_[i];
      if (!(d > 0.0)) {
        wall_hist_[hw] = TangentialHistory();
        wall_touching_[hw] = 0;
        continue;
      }
      max_overlap = std::max(max_overlap, best);
      const Vector3d r = x_[i] - q_best;
      const Vector3d nrm = r / r.norm();
      const Vector3d vw = wl.velocity + wl.angular_velocity.cross(q_best - wl.position);
      const Vector3d vr = v_[i] - vw;
      const double vn = vr.dot(nrm);
      const SoilContactLaw& wlaw = wall_law_[w];
      const SoilNormalForce fn = wlaw.Normal(d, -vn, wl.adhesion_factor * adhesion_max_[i]);
      const Vector3d ft = wlaw.Tangential(nrm, vr - vn * nrm, fn.repulsion, dt, &wall_hist_[hw]);
      const Vector3d fc = fn.Total() * nrm + ft;
      f += fc;
      max_rep = std::max(max_rep, fn.repulsion);
      wall_touching_[hw] = 1;
      wall_force_[hw] = -fc;
      wall_moment_[hw] = (q_best - wl.wrench_point).cross(-fc);
    }
    f_[i] = f;
    max_repulsion_[i] = max_rep;
    overlap_[i] = max_overlap;
  }
  ComputeWallForces();
}

void DemSystem::ComputeWallForces() {
  // summed in particle order, whatever the thread count
  const int W = num_walls(), n = size();
  for (int w = 0; w < W; ++w) {
    DemWall& wl = walls_[w];
    wl.force.setZero();
    wl.moment.setZero();
    wl.contacts = 0;
    for (int i = 0; i < n; ++i) {
      const size_t hw = static_cast<size_t>(i) * W + w;
      if (!wall_touching_[hw]) continue;
      wl.force += wall_force_[hw];
      wl.moment += wall_moment_[hw];
      ++wl.contacts;
    }
  }
}

void DemSystem::Step() {
  DM_DEMAND(finalized_);
  const int n = size();
  const double h = 0.5 * dt_, half_skin = 0.5 * settings_.skin * soil_.diameter;
  const double inv_m = 1.0 / mass_;
  double max_disp2 = 0.0;
#pragma omp parallel for schedule(static) num_threads(settings_.threads) reduction(max : max_disp2)
  for (int i = 0; i < n; ++i) {
    v_[i] += h * inv_m * f_[i];
    x_[i] += dt_ * v_[i];
    max_disp2 = std::max(max_disp2, (x_[i] - x_built_[i]).squaredNorm());
  }
  time_ += dt_;
  ++step_;
  CheckState();
  UpdateWallVertices();  // the walls' poses were set for this step from outside
  if (rebuild_ || max_disp2 > half_skin * half_skin || MaxWallDisplacement() > half_skin) BuildNeighbours();
  ComputeForces();
  CheckOverlaps();
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    v_[i] += h * inv_m * f_[i];
    plastic_[i] = UpdatePlasticDeformation(soil_, plastic_[i], max_repulsion_[i], dt_);
    adhesion_max_[i] = MaxAdhesionForce(soil_, plastic_[i]);
  }
}

void DemSystem::CheckState() const {
  const int n = size();
  const double half_skin = 0.5 * settings_.skin * soil_.diameter;
  for (int i = 0; i < n; ++i) {
    if (!(x_[i].allFinite() && v_[i].allFinite()))
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", i,
                                           " has a non-finite state (x = ", x_[i].transpose(), ", v = ",
                                           v_[i].transpose(), "); the time step is too large or an input is NaN"));
    const double move = v_[i].norm() * dt_;
    if (move > half_skin)
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", i, " moved ", move,
                                           " m in one step, more than half the skin (", half_skin,
                                           " m); its speed is ", v_[i].norm(), " m/s"));
  }
}

void DemSystem::CheckOverlaps() const {
  const double D = soil_.diameter, limit = settings_.max_overlap * D;
  for (int i = 0; i < size(); ++i)
    if (overlap_[i] > limit || !f_[i].allFinite())
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", i,
                                           !f_[i].allFinite() ? " has a non-finite force" : " overlaps a neighbour by ",
                                           overlap_[i] / D, " of the diameter (limit ", settings_.max_overlap, ")"));
}

int DemSystem::contacts() const {
  int c = 0;
  for (unsigned char t : touching_) c += t;
  return c;
}

DemEnergy DemSystem::Energy() const {
  DemEnergy e;
  const double D = soil_.diameter, d0 = soil_.adhesion_depth * D, dp = soil_.adhesion_peak * D;
  const double kn = soil_.NormalStiffness(), kt = soil_.TangentialStiffness();
  for (int i = 0; i < size(); ++i) {
    e.kinetic += 0.5 * mass_ * v_[i].squaredNorm();
    e.gravitational -= mass_ * gravity_.dot(x_[i]);
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_[k];
      if (!touching_[k]) continue;
      const double d = (D - (x_[i] - x_[j]).norm()) - (plastic_[i] + plastic_[j]);
      double u = 0.5 * kt * hist_[k].spring.squaredNorm();
      if (d > d0) u += 0.5 * kn * (d - d0) * (d - d0);
      const double fmax = std::min(adhesion_max_[i], adhesion_max_[j]);
      if (soil_.cohesion && fmax > 0.0 && d > 0.0 && dp > 0.0) {
        // potential of the adhesion triangle, zero out of contact: -(area from 0 to min(d, d0))
        const double a = std::min(d, d0);
        const double w = a <= dp ? 0.5 * fmax * a * a / dp
                                 : 0.5 * fmax * dp + fmax * (a - dp) - 0.5 * fmax * (a - dp) * (a - dp) / (d0 - dp);
        u -= w;
      }
      e.elastic += u;
    }
  }
  return e;
}

size_t DemSystem::MemoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  size_t b = bytes(x_) + bytes(v_) + bytes(f_) + bytes(x_built_) + bytes(plastic_) + bytes(adhesion_max_) +
             bytes(max_repulsion_) + bytes(overlap_) + bytes(nbr_start_) + bytes(nbr_) + bytes(hist_) +
             bytes(pair_force_) + bytes(pair_rep_) + bytes(pair_overlap_) + bytes(rev_start_) + bytes(rev_) +
             bytes(touching_) + bytes(wall_hist_) + bytes(wall_touching_) + bytes(particle_tri_start_) +
             bytes(particle_tris_) + bytes(wall_force_) + bytes(wall_moment_);
  return b;
}

Vector3d DemSystem::Momentum() const {
  Vector3d p = Vector3d::Zero();
  for (const Vector3d& v : v_) p += mass_ * v;
  return p;
}

}  // namespace dem_mobility
