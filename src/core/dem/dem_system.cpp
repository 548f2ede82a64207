#include "dem_mobility/core/dem/dem_system.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/time_step.h"

namespace dem_mobility {

using Eigen::Vector3d;


DemSystem::DemSystem(const SoilParams& soil, const DemSettings& settings)
    : soil_(soil), settings_(settings), law_(soil) {
  DM_THROW_UNLESS(settings.skin > 0.0 && settings.skin <= 1.0, "DEM skin ", settings.skin,
                  " (fraction of the diameter) must lie in (0, 1]");
  DM_THROW_UNLESS(settings.threads >= 1, "DEM threads ", settings.threads, " must be >= 1");
  DM_THROW_UNLESS(settings.max_overlap > 0.0 && settings.max_overlap < 1.0, "DEM max_overlap ",
                  settings.max_overlap, " must lie in (0, 1)");
  DM_THROW_UNLESS(settings.list_slack >= 0, "DEM list_slack ", settings.list_slack, " must be >= 0");
  mass_ = soil.Mass();
  cutoff_ = soil.diameter * (1.0 + settings.skin);
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
  // one contact history per particle and wall (nothing has touched yet: walls come before Finalize)
  wall_hist_.assign(x_.size() * walls_.size(), TangentialHistory());
  wall_touching_.assign(x_.size() * walls_.size(), 0);
  rebuild_ = true;
  return static_cast<int>(walls_.size()) - 1;
}

// ---------------------------------------------------------------------------------------------
// particles in and out

int DemSystem::AddParticle(const Vector3d& x, const Vector3d& v) {
  DM_THROW_UNLESS(x.allFinite() && v.allFinite(), "particle ", size(), ": position and velocity must be finite");
  const int id = size();
  int p;
  if (!free_slots_.empty()) {  // the lowest free slot
    p = free_slots_.front();
    free_slots_.erase(free_slots_.begin());
    const int old_id = id_of_slot_[p];  // the removed particle's last state is gone now
    if (old_id >= 0) slot_of_id_[old_id] = -1;
  } else {
    p = static_cast<int>(x_.size());
    x_.emplace_back();
    v_.emplace_back();
    f_.emplace_back();
    x_built_.emplace_back();
    plastic_.push_back(0.0);
    adhesion_max_.push_back(0.0);
    max_repulsion_.push_back(0.0);
    max_tension_.push_back(0.0);
    overlap_.push_back(0.0);
    alive_.push_back(0);
    slab_of_.push_back(0);
    id_of_slot_.push_back(-1);
    const size_t W = walls_.size();
    wall_hist_.resize(wall_hist_.size() + W);
    wall_touching_.resize(wall_touching_.size() + W, 0);
    if (finalized_) {
      nbr_begin_.push_back(static_cast<int>(nbr_.size()));
      nbr_end_.push_back(nbr_begin_.back());
      nbr_cap_.push_back(nbr_begin_.back());
      particle_tri_start_.push_back(particle_tri_start_.back());
    }
  }
  slot_of_id_.push_back(p);
  id_of_slot_[p] = id;
  x_[p] = x;
  v_[p] = v;
  f_[p] = mass_ * gravity_;  // its contacts act from its first force evaluation on
  x_built_[p] = x;
  plastic_[p] = 0.0;
  adhesion_max_[p] = MaxAdhesionForce(soil_, 0.0);
  max_repulsion_[p] = max_tension_[p] = overlap_[p] = 0.0;
  const size_t W = walls_.size();
  for (size_t w = 0; w < W; ++w) {
    wall_hist_[p * W + w] = TangentialHistory();
    wall_touching_[p * W + w] = 0;
  }
  if (!finalized_) {  // the first build lists it
    alive_[p] = 1;
    rebuild_ = true;
    return id;
  }
  alive_[p] = 2;  // added since the last build
  added_since_build_.push_back(p);
  InsertNeighbours(p);
  exchanged_ += ParticleEnergy(slot_of_id_[id]);  // (a rebuild may have moved it)
  return id;
}

void DemSystem::RemoveParticle(int id) {
  DM_THROW_UNLESS(id >= 0 && id < size() && alive(id), "RemoveParticle: ", id, " is not a particle");
  const int i = slot_of_id_[id];
  if (finalized_) {
    exchanged_ -= ParticleEnergy(i);
    // its pairs: those it owns, and those its neighbours own
    nbr_end_[i] = nbr_begin_[i];
    for (int j : NeighbourCandidates(x_built_[i]))
      if (j != i && Owns(j, i)) RemovePair(j, i);
    if (alive_[i] == 2) {
      std::vector<int>& added = slab_added_[slab_of_[i]];
      added.erase(std::find(added.begin(), added.end(), i));
    }
    const size_t W = walls_.size();
    for (size_t w = 0; w < W; ++w) {
      wall_hist_[i * W + w] = TangentialHistory();
      wall_touching_[i * W + w] = 0;
    }
  }
  alive_[i] = 0;
  f_[i].setZero();
  max_repulsion_[i] = max_tension_[i] = overlap_[i] = 0.0;
  slot_of_id_[id] = -2 - i;  // removed; its last state stays readable until the slot is reused
  ++removed_;
  free_slots_.insert(std::lower_bound(free_slots_.begin(), free_slots_.end(), i), i);
}

void DemSystem::set_threads(int threads) {
  DM_THROW_UNLESS(threads >= 1, "DEM threads ", threads, " must be >= 1");
  settings_.threads = threads;
}

int DemSystem::LiveSlot(int id) const {
  DM_THROW_UNLESS(id >= 0 && id < size() && slot_of_id_[id] >= 0, "particle ", id, " is not a live particle");
  return slot_of_id_[id];
}

std::vector<Vector3d> DemSystem::positions() const {
  std::vector<Vector3d> out(size());
  for (int id = 0; id < size(); ++id) out[id] = position(id);
  return out;
}

std::vector<Vector3d> DemSystem::velocities() const {
  std::vector<Vector3d> out(size());
  for (int id = 0; id < size(); ++id) out[id] = velocity(id);
  return out;
}

std::vector<double> DemSystem::plastic_deformations() const {
  std::vector<double> out(size());
  for (int id = 0; id < size(); ++id) out[id] = plastic_deformation(id);
  return out;
}

// ---------------------------------------------------------------------------------------------
// the grid, the slabs and the neighbour lists

Eigen::Vector3i DemSystem::CellOf(const Vector3d& x) const {
  // clamped: a particle outside the grid's box lands in a border cell, whose neighbour cells
  // still hold every particle within one cell width of it
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const double u = std::floor((x[a] - grid_lo_[a]) / cutoff_);
    c[a] = u < 0.0 ? 0 : u >= grid_dims_[a] - 1 ? grid_dims_[a] - 1 : static_cast<int>(u);
  }
  return c;
}

std::vector<int> DemSystem::NeighbourCandidates(const Vector3d& x) const {
  // the slots of the last build in the 27 cells about x, and those added since
  std::vector<int> out;
  ForEachSlotNear(CellOf(x), [&](int j) {
    if (alive_[j] == 1) out.push_back(j);
  });
  for (int j : added_since_build_)
    if (alive_[j] == 2) out.push_back(j);
  return out;
}

void DemSystem::SortSlots(const std::vector<long>& cell) {
  // a stable counting sort of the live slots by cell (slab-major: the slab axis is the slowest),
  // the free slots last
  const int n = static_cast<int>(x_.size());
  const long ncell = static_cast<long>(cell_start_.size()) - 1;
  std::vector<int> order;  // order[new slot] = old slot
  order.reserve(n);
  {
    std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
    order.resize(cell_start_[ncell]);
    for (int i = 0; i < n; ++i)
      if (cell[i] >= 0) order[fill[cell[i]]++] = i;
    for (int i = 0; i < n; ++i)
      if (cell[i] < 0) order.push_back(i);
  }
  auto permute = [&](auto& v, size_t width) {
    auto old = v;
    for (int s = 0; s < n; ++s)
      std::copy(old.begin() + static_cast<size_t>(order[s]) * width,
                old.begin() + static_cast<size_t>(order[s] + 1) * width, v.begin() + static_cast<size_t>(s) * width);
  };
  permute(x_, 1);
  permute(v_, 1);
  permute(f_, 1);
  permute(plastic_, 1);
  permute(adhesion_max_, 1);
  permute(max_repulsion_, 1);
  permute(max_tension_, 1);
  permute(overlap_, 1);
  permute(alive_, 1);
  permute(id_of_slot_, 1);
  permute(wall_hist_, walls_.size());
  permute(wall_touching_, walls_.size());
  // the old neighbour lists stay where they are, reached through the old slot numbers
  std::vector<int> begin(n), end(n);
  for (int s = 0; s < n; ++s) {
    begin[s] = nbr_begin_[order[s]];
    end[s] = nbr_end_[order[s]];
  }
  nbr_begin_.swap(begin);
  nbr_end_.swap(end);
  std::vector<int> new_of_old(n);
  for (int s = 0; s < n; ++s) new_of_old[order[s]] = s;
  for (int& j : nbr_) j = j >= 0 ? new_of_old[j] : j;
  free_slots_.clear();
  for (int s = 0; s < n; ++s) {
    if (alive_[s]) {
      slot_of_id_[id_of_slot_[s]] = s;
    } else {
      free_slots_.push_back(s);
      if (id_of_slot_[s] >= 0) slot_of_id_[id_of_slot_[s]] = -2 - s;
    }
  }
}

const TangentialHistory* DemSystem::FindHistory(int i, int j) const {
  for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k)
    if (nbr_[k] == j) return touching_[k] ? &hist_[k] : nullptr;
  return nullptr;
}

void DemSystem::BuildNeighbours() {
  const int n = static_cast<int>(x_.size());
  // a uniform grid of cells one cutoff wide over the live particles' bounding box; slabs of whole
  // cells, at least one cutoff thick, at most 64, along the longest axis, which is made the
  // slowest-varying one of the cell index
  Vector3d lo = Vector3d::Constant(1e300), hi = -lo;
  for (int i = 0; i < n; ++i)
    if (alive_[i]) {
      lo = lo.cwiseMin(x_[i]);
      hi = hi.cwiseMax(x_[i]);
    }
  if (lo.x() > hi.x()) lo = hi = Vector3d::Zero();
  grid_lo_ = lo;
  for (int a = 0; a < 3; ++a) grid_dims_[a] = std::max(1, static_cast<int>((hi[a] - lo[a]) / cutoff_) + 1);
  slab_axis_ = 0;
  for (int a = 1; a < 3; ++a)
    if (grid_dims_[a] > grid_dims_[slab_axis_]) slab_axis_ = a;
  const int a1 = (slab_axis_ + 1) % 3, a2 = (slab_axis_ + 2) % 3;
  grid_stride_[a1] = 1;
  grid_stride_[a2] = grid_dims_[a1];
  grid_stride_[slab_axis_] = static_cast<long>(grid_dims_[a1]) * grid_dims_[a2];
  const long ncell = static_cast<long>(grid_dims_.x()) * grid_dims_.y() * grid_dims_.z();
  cells_per_slab_ = std::max(1, (grid_dims_[slab_axis_] + 63) / 64);
  const int ns = (grid_dims_[slab_axis_] + cells_per_slab_ - 1) / cells_per_slab_;

  std::vector<long> cell(n, -1);
  cell_start_.assign(ncell + 1, 0);
  for (int i = 0; i < n; ++i)
    if (alive_[i]) {
      cell[i] = CellIndex(CellOf(x_[i]));
      ++cell_start_[cell[i] + 1];
    }
  for (long c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  // the old lists (valid once built) are carried through the sort for the contact histories
  const bool have_old = static_cast<int>(nbr_begin_.size()) == n;
  if (!have_old) {
    nbr_begin_.assign(n, 0);
    nbr_end_.assign(n, 0);
  }
  SortSlots(cell);
  slab_start_.assign(ns + 1, 0);
  {
    Eigen::Vector3i c = Eigen::Vector3i::Zero();
    for (int s = 0; s < ns; ++s) {
      c[slab_axis_] = s * cells_per_slab_;
      slab_start_[s] = cell_start_[CellIndex(c)];
    }
    slab_start_[ns] = cell_start_[ncell];
  }
  for (int s = 0; s < ns; ++s)
    for (int i = slab_start_[s]; i < slab_start_[s + 1]; ++i) slab_of_[i] = s;
  slab_added_.assign(ns, {});

  // each slot's partners within the cutoff in the pairs it owns (half list), ascending
  const double cut2 = cutoff_ * cutoff_;
  const int live = cell_start_[ncell];
  std::vector<std::vector<int>> found(live);
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < live; ++i) {
    std::vector<int>& out = found[i];
    ForEachSlotNear(CellOf(x_[i]), [&](int j) {
      if (j != i && Owns(i, j) && (x_[i] - x_[j]).squaredNorm() < cut2) out.push_back(j);
    });
    std::sort(out.begin(), out.end());
  }
  // the lists in slot order, each with room for settings_.list_slack more
  const int slack = settings_.list_slack;
  std::vector<int> begin(n), end(n), cap(n);
  int total = 0;
  for (int i = 0; i < n; ++i) {
    begin[i] = total;
    end[i] = total + (i < live ? static_cast<int>(found[i].size()) : 0);
    cap[i] = i < live ? end[i] + slack : end[i];
    total = cap[i];
  }
  std::vector<int> nbr(total, -1);
  std::vector<TangentialHistory> hist(total);
  std::vector<unsigned char> touching(total, 0);
  if (!have_old) nbr_.clear();
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < live; ++i) {
    // carry each surviving contact's history over, from whichever side owned it before
    for (int k = begin[i], m = 0; k < end[i]; ++k, ++m) {
      const int j = found[i][m];
      nbr[k] = j;
      if (const TangentialHistory* h = FindHistory(i, j)) {
        hist[k] = *h;
        touching[k] = 1;
      } else if (const TangentialHistory* g = FindHistory(j, i)) {
        hist[k].spring = -g->spring;
        touching[k] = 1;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    x_built_[i] = x_[i];
    if (alive_[i]) alive_[i] = 1;
  }
  nbr_begin_.swap(begin);
  nbr_end_.swap(end);
  nbr_cap_.swap(cap);
  nbr_.swap(nbr);
  hist_.swap(hist);
  touching_.swap(touching);
  added_since_build_.clear();

  // walls: each slot's candidate triangles, those whose box (grown by the cutoff) holds it
  const int W = num_walls();
  UpdateWallVertices();
  wall_tris_.clear();
  wall_built_vertices_ = wall_vertices_;
  for (int w = 0; w < W; ++w)
    for (int f = 0; f < static_cast<int>(walls_[w].mesh.faces.size()); ++f) wall_tris_.push_back({w, f});
  std::vector<std::vector<int>> cand(n);
  if (!wall_tris_.empty()) {
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
    for (int i = 0; i < live; ++i)
      for (int t = 0; t < static_cast<int>(wall_tris_.size()); ++t) {
        const WallTri& tr = wall_tris_[t];
        const auto& face = walls_[tr.wall].mesh.faces[tr.face];
        const std::vector<Vector3d>& wv = wall_vertices_[tr.wall];
        const Vector3d tlo = wv[face[0]].cwiseMin(wv[face[1]]).cwiseMin(wv[face[2]]).array() - cutoff_;
        const Vector3d thi = wv[face[0]].cwiseMax(wv[face[1]]).cwiseMax(wv[face[2]]).array() + cutoff_;
        if ((x_[i].array() >= tlo.array()).all() && (x_[i].array() <= thi.array()).all()) cand[i].push_back(t);
      }
  }
  particle_tri_start_.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) particle_tri_start_[i + 1] = particle_tri_start_[i] + static_cast<int>(cand[i].size());
  particle_tris_.resize(particle_tri_start_[n]);
  for (int i = 0; i < n; ++i) std::copy(cand[i].begin(), cand[i].end(), particle_tris_.begin() + particle_tri_start_[i]);
  rebuild_ = false;
  ++builds_;
}

void DemSystem::InsertNeighbours(int p) {
  // its neighbours at their positions at the last build (or at their addition): as in a build,
  // so the skin guarantee holds for the new pairs. Its slab from where it is: within a cutoff of
  // its neighbours' positions, so at most one slab from theirs.
  const double cut2 = cutoff_ * cutoff_;
  const Vector3d& xp = x_[p];
  slab_of_[p] = SlabOfCell(CellOf(xp));
  slab_added_[slab_of_[p]].push_back(p);
  std::vector<int> found;
  for (int j : NeighbourCandidates(xp))
    if (j != p && (x_built_[j] - xp).squaredNorm() < cut2) found.push_back(j);
  std::sort(found.begin(), found.end());
  // the pairs it owns in a list of its own at the end of the pool, with room to spare
  std::vector<int> own;
  for (int j : found)
    if (Owns(p, j)) own.push_back(j);
  nbr_begin_[p] = static_cast<int>(nbr_.size());
  nbr_end_[p] = nbr_begin_[p] + static_cast<int>(own.size());
  nbr_cap_[p] = nbr_end_[p] + settings_.list_slack;
  nbr_.insert(nbr_.end(), own.begin(), own.end());
  nbr_.resize(nbr_cap_[p], -1);
  hist_.resize(nbr_cap_[p]);
  touching_.resize(nbr_cap_[p], 0);
  for (int k = nbr_begin_[p]; k < nbr_cap_[p]; ++k) {
    hist_[k] = TangentialHistory();
    touching_[k] = 0;
  }
  for (int j : found)
    if (!Owns(p, j) && !InsertPair(j, p)) {  // no room left in j's list: rebuild all lists now
      ++overflow_builds_;
      BuildNeighbours();
      return;
    }
}

bool DemSystem::InsertPair(int i, int j) {
  if (nbr_end_[i] == nbr_cap_[i]) return false;
  int k = nbr_end_[i];
  while (k > nbr_begin_[i] && nbr_[k - 1] > j) {  // keep the list ascending
    nbr_[k] = nbr_[k - 1];
    hist_[k] = hist_[k - 1];
    touching_[k] = touching_[k - 1];
    --k;
  }
  nbr_[k] = j;
  hist_[k] = TangentialHistory();
  touching_[k] = 0;
  ++nbr_end_[i];
  return true;
}

void DemSystem::RemovePair(int i, int j) {
  int k = nbr_begin_[i];
  while (k < nbr_end_[i] && nbr_[k] != j) ++k;
  if (k == nbr_end_[i]) return;
  for (; k + 1 < nbr_end_[i]; ++k) {
    nbr_[k] = nbr_[k + 1];
    hist_[k] = hist_[k + 1];
    touching_[k] = touching_[k + 1];
  }
  --nbr_end_[i];
}

// ---------------------------------------------------------------------------------------------
// time stepping

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

TimeStepLimit DemSystem::CriticalTimeStep() const {
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
  TimeStepLimit lim;
  lim.dt_crit = CriticalStep(omega, zeta);
  lim.element = "soil particle contact";
  lim.detail = detail::Concat(branch, " stiffness ", k, " N/m from ", settings_.max_coordination,
                              " neighbours on a particle of ", mass_, " kg (damping ratio ", zeta, ")");
  return lim;
}

void DemSystem::Finalize(double dt) {
  const TimeStepLimit lim = CriticalTimeStep();
  DM_THROW_UNLESS(std::isfinite(dt) && dt > 0.0, "DEM time step ", dt, " s must be positive");
  DM_THROW_UNLESS(dt <= lim.dt_crit, "DEM time step ", dt, " s is above the critical step ", lim.dt_crit, " s (",
                  lim.detail, "); use dt <= ", lim.dt_crit, " s");
  dt_ = dt;
  BuildNeighbours();
  finalized_ = true;
  ComputeForces();
  e0_ = Mechanical().Total();
  wall_work_ = exchanged_ = 0.0;
}

void DemSystem::set_gravity(const Vector3d& g) {
  // a change of gravity during a run changes the particles' potential energy: from outside
  if (finalized_)
    for (size_t i = 0; i < x_.size(); ++i)
      if (alive_[i]) exchanged_ -= mass_ * (g - gravity_).dot(x_[i]);
  gravity_ = g;
}

void DemSystem::ComputeForces() {
  const int n = static_cast<int>(x_.size());
  const double D = soil_.diameter, D2 = D * D, dt = dt_;
  const Vector3d weight = mass_ * gravity_;
  const int W = num_walls(), all_tris = static_cast<int>(wall_tris_.size());
  const int T = settings_.threads;
#pragma omp parallel for schedule(static) num_threads(T)
  for (int i = 0; i < n; ++i) {
    f_[i] = alive_[i] ? weight : Vector3d::Zero();
    max_repulsion_[i] = max_tension_[i] = overlap_[i] = 0.0;
  }
  // the pairs, slab by slab: the even slabs in parallel, then the odd ones (see the header)
  auto sweep = [&](int i) {
    const Vector3d xi = x_[i], vi = v_[i];
    const double pi = plastic_[i], ai = adhesion_max_[i];
    Vector3d fi = Vector3d::Zero();
    double max_rep = max_repulsion_[i], max_ten = max_tension_[i], max_overlap = overlap_[i];
    for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k) {
      const int j = nbr_[k];
      const Vector3d r = xi - x_[j];
      const double r2 = r.squaredNorm();
      if (r2 >= D2) {  // in the skin, not touching
        if (touching_[k]) {
          hist_[k] = TangentialHistory();
          touching_[k] = 0;
        }
        continue;
      }
      const double dist = std::sqrt(r2);
      const double overlap = D - dist;
      max_overlap = std::max(max_overlap, overlap);
      overlap_[j] = std::max(overlap_[j], overlap);
      // effective penetration: the overlap less both particles' plastic deformation
      const double d = overlap - (pi + plastic_[j]);
      if (!(d > 0.0) || dist <= 0.0) {
        if (touching_[k]) {
          hist_[k] = TangentialHistory();
          touching_[k] = 0;
        }
        continue;
      }
      const Vector3d nrm = r * (1.0 / dist);  // from j toward i
      const Vector3d vr = vi - v_[j];
      const double vn = vr.dot(nrm);
      const SoilNormalForce fn = law_.Normal(d, -vn, std::min(ai, adhesion_max_[j]));
      const Vector3d vt = vr - vn * nrm;
      const Vector3d fc = fn.Total() * nrm + law_.Tangential(nrm, vt, fn.repulsion, dt, &hist_[k]);
      fi += fc;
      f_[j] -= fc;
      max_rep = std::max(max_rep, fn.repulsion);
      max_ten = std::max(max_ten, -fn.adhesion);
      max_repulsion_[j] = std::max(max_repulsion_[j], fn.repulsion);
      max_tension_[j] = std::max(max_tension_[j], -fn.adhesion);
      touching_[k] = 1;
    }
    f_[i] += fi;
    max_repulsion_[i] = max_rep;
    max_tension_[i] = max_ten;
    overlap_[i] = max_overlap;
  };
  const int ns = static_cast<int>(slab_added_.size());
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(T)
    for (int sl = colour; sl < ns; sl += 2) {
      for (int i = slab_start_[sl]; i < slab_start_[sl + 1]; ++i)
        if (alive_[i] == 1) sweep(i);
      for (const int i : slab_added_[sl]) sweep(i);
    }
  }
  if (W == 0) {
    wall_power_ = 0.0;
    return;
  }
  // walls: per wall the deepest of the candidate triangles (a particle added since the last build
  // tries them all). The wrenches are summed in fixed chunks of slots, in slot order, and the chunks
  // in order: the same sums for any thread count, without a force per particle and wall.
  constexpr int kChunk = 4096;
  const int chunks = (n + kChunk - 1) / kChunk;
  wall_chunk_.assign(static_cast<size_t>(chunks) * W, WallSum());
#pragma omp parallel for schedule(dynamic, 1) num_threads(T)
  for (int c = 0; c < chunks; ++c) {
    WallSum* sum = &wall_chunk_[static_cast<size_t>(c) * W];
    for (int i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (!alive_[i]) continue;
      const bool fresh = alive_[i] == 2;
      const int t_begin = fresh ? 0 : particle_tri_start_[i], t_end = fresh ? all_tris : particle_tri_start_[i + 1];
      if (t_begin == t_end) {  // no wall near: clear what an earlier contact left
        for (int w = 0; w < W; ++w) {
          const size_t hw = static_cast<size_t>(i) * W + w;
          if (wall_touching_[hw]) {
            wall_hist_[hw] = TangentialHistory();
            wall_touching_[hw] = 0;
          }
        }
        continue;
      }
      const Vector3d xi = x_[i], vi = v_[i];
      const double pi = plastic_[i], ai = adhesion_max_[i];
      Vector3d f = f_[i];
      double max_rep = max_repulsion_[i], max_ten = max_tension_[i], max_overlap = overlap_[i];
      // the candidates come in wall order: one pass over them, a group per wall
      auto tri_at = [&](int t) -> const WallTri& { return wall_tris_[fresh ? t : particle_tris_[t]]; };
      int t = t_begin;
      for (int w = 0; w < W; ++w) {
        const size_t hw = static_cast<size_t>(i) * W + w;
        if (t == t_end || tri_at(t).wall != w) {  // no triangle of this wall near
          if (wall_touching_[hw]) {
            wall_hist_[hw] = TangentialHistory();
            wall_touching_[hw] = 0;
          }
          continue;
        }
        const DemWall& wl = walls_[w];
        double best = 0.0;
        Vector3d q_best = Vector3d::Zero();
        for (; t < t_end && tri_at(t).wall == w; ++t) {
          const WallTri& tr = tri_at(t);
          // the triangle where the wall is now (it may have moved since the build)
          const auto& face = wl.mesh.faces[tr.face];
          const std::vector<Vector3d>& wv = wall_vertices_[w];
          const Vector3d q = ClosestPointOnTriangle(xi, wv[face[0]], wv[face[1]], wv[face[2]]);
          const double overlap = 0.5 * D - (xi - q).norm();
          if (overlap > best) {
            best = overlap;
            q_best = q;
          }
        }
        const double d = best - pi;
        if (!(d > 0.0)) {
          wall_hist_[hw] = TangentialHistory();
          wall_touching_[hw] = 0;
          continue;
        }
        max_overlap = std::max(max_overlap, best);
        const Vector3d r = xi - q_best;
        const Vector3d nrm = r / r.norm();
        const Vector3d vw = wl.velocity + wl.angular_velocity.cross(q_best - wl.position);
        const Vector3d vr = vi - vw;
        const double vn = vr.dot(nrm);
        const SoilContactLaw& wlaw = wall_law_[w];
        const SoilNormalForce fn = wlaw.Normal(d, -vn, wl.adhesion_factor * ai);
        const Vector3d ft = wlaw.Tangential(nrm, vr - vn * nrm, fn.repulsion, dt, &wall_hist_[hw]);
        const Vector3d fc = fn.Total() * nrm + ft;
        f += fc;
        max_rep = std::max(max_rep, fn.repulsion);
        max_ten = std::max(max_ten, -fn.adhesion);
        wall_touching_[hw] = 1;
        sum[w].force -= fc;
        sum[w].moment += (q_best - wl.wrench_point).cross(-fc);
        sum[w].power += fc.dot(vw);  // the wall's work on the particle, per unit time
        ++sum[w].contacts;
      }
      f_[i] = f;
      max_repulsion_[i] = max_rep;
      max_tension_[i] = max_ten;
      overlap_[i] = max_overlap;
    }
  }
  wall_power_ = 0.0;
  for (int w = 0; w < W; ++w) {
    DemWall& wl = walls_[w];
    wl.force.setZero();
    wl.moment.setZero();
    wl.contacts = 0;
    for (int c = 0; c < chunks; ++c) {
      const WallSum& cs = wall_chunk_[static_cast<size_t>(c) * W + w];
      wl.force += cs.force;
      wl.moment += cs.moment;
      wl.contacts += cs.contacts;
      wall_power_ += cs.power;
    }
  }
}

void DemSystem::Step() {
  DM_DEMAND(finalized_);
  const int n = static_cast<int>(x_.size());
  const double h = 0.5 * dt_, half_skin = 0.5 * settings_.skin * soil_.diameter;
  const double inv_m = 1.0 / mass_;
  double max_disp2 = 0.0;
#pragma omp parallel for schedule(static) num_threads(settings_.threads) reduction(max : max_disp2)
  for (int i = 0; i < n; ++i) {
    if (!alive_[i]) continue;
    v_[i] += h * inv_m * f_[i];
    x_[i] += dt_ * v_[i];
    max_disp2 = std::max(max_disp2, (x_[i] - x_built_[i]).squaredNorm());
  }
  time_ += dt_;
  ++step_;
  CheckState();
  UpdateWallVertices();  // the walls' poses were set for this step from outside
  if (rebuild_ || max_disp2 > half_skin * half_skin || MaxWallDisplacement() > half_skin) BuildNeighbours();
  const double power_before = wall_power_;
  ComputeForces();
  wall_work_ += h * (power_before + wall_power_);  // trapezoidal
  CheckOverlaps();
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
  for (int i = 0; i < n; ++i) {
    if (!alive_[i]) continue;
    v_[i] += h * inv_m * f_[i];
    const double dp = UpdatePlasticDeformation(soil_, plastic_[i], max_repulsion_[i], max_tension_[i], dt_);
    if (dp != plastic_[i]) {
      plastic_[i] = dp;
      adhesion_max_[i] = MaxAdhesionForce(soil_, dp);
    }
  }
}

void DemSystem::CheckState() const {
  const int n = static_cast<int>(x_.size());
  const double half_skin = 0.5 * settings_.skin * soil_.diameter;
  for (int i = 0; i < n; ++i) {
    if (!alive_[i]) continue;
    if (!(x_[i].allFinite() && v_[i].allFinite()))
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", id_of_slot_[i],
                                           " has a non-finite state (x = ", x_[i].transpose(), ", v = ",
                                           v_[i].transpose(), "); the time step is too large or an input is NaN"));
    const double move = v_[i].norm() * dt_;
    if (move > half_skin)
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", id_of_slot_[i],
                                           " moved ", move, " m in one step, more than half the skin (", half_skin,
                                           " m); its speed is ", v_[i].norm(), " m/s"));
  }
}

void DemSystem::CheckOverlaps() const {
  const double D = soil_.diameter, limit = settings_.max_overlap * D;
  for (size_t i = 0; i < x_.size(); ++i)
    if (alive_[i] && (overlap_[i] > limit || !f_[i].allFinite()))
      throw SimulationError(detail::Concat("DEM step ", step_, " (t = ", time_, " s): particle ", id_of_slot_[i],
                                           !f_[i].allFinite() ? " has a non-finite force" : " overlaps a neighbour by ",
                                           overlap_[i] / D, " of the diameter (limit ", settings_.max_overlap, ")"));
}

// ---------------------------------------------------------------------------------------------
// energy and bookkeeping

int DemSystem::contacts() const {
  int c = 0;
  for (size_t i = 0; i < x_.size(); ++i)
    for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k) c += touching_[k];
  return c;
}

double DemSystem::PairEnergy(int i, int k) const {
  // the elastic energy stored in one contact: its normal branches (repulsion, and the adhesion
  // triangle's potential, zero out of contact) and its anchor spring
  const int j = nbr_[k];
  const double d = (soil_.diameter - (x_[i] - x_[j]).norm()) - (plastic_[i] + plastic_[j]);
  const double fmax = std::min(adhesion_max_[i], adhesion_max_[j]);
  double u = touching_[k] ? 0.5 * law_.k_t * hist_[k].spring.squaredNorm() : 0.0;
  if (!(d > 0.0)) return u;
  const double d0 = law_.d0, dp = law_.dp;
  if (d > d0) u += 0.5 * law_.k_n * (d - d0) * (d - d0);
  if (law_.cohesion && fmax > 0.0 && dp > 0.0) {
    const double a = std::min(d, d0);
    u -= a <= dp ? 0.5 * fmax * a * a / dp : 0.5 * fmax * dp + fmax * (a - dp) - 0.5 * fmax * (a - dp) * (a - dp) / (d0 - dp);
  }
  return u;
}

EnergyReport DemSystem::Mechanical() const {
  EnergyReport e;
  for (size_t i = 0; i < x_.size(); ++i) {
    if (!alive_[i]) continue;
    e.kinetic += 0.5 * mass_ * v_[i].squaredNorm();
    e.gravitational -= mass_ * gravity_.dot(x_[i]);
    for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k) e.elastic += PairEnergy(static_cast<int>(i), k);
  }
  return e;
}

double DemSystem::ParticleEnergy(int i) const {
  double u = 0.5 * mass_ * v_[i].squaredNorm() - mass_ * gravity_.dot(x_[i]);
  for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k) u += PairEnergy(i, k);
  for (int j : NeighbourCandidates(x_built_[i]))
    if (j != i)
      for (int k = nbr_begin_[j]; k < nbr_end_[j]; ++k)
        if (nbr_[k] == i) u += PairEnergy(j, k);
  return u;
}

EnergyReport DemSystem::Energy() const {
  EnergyReport e = Mechanical();
  if (!finalized_) return e;
  e.wall_work = wall_work_;
  e.exchanged = exchanged_;
  e.dissipated = wall_work_ + exchanged_ - (e.Total() - e0_);
  return e;
}

size_t DemSystem::MemoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  size_t b = bytes(x_) + bytes(v_) + bytes(f_) + bytes(x_built_) + bytes(plastic_) + bytes(adhesion_max_) +
             bytes(max_repulsion_) + bytes(max_tension_) + bytes(overlap_) + bytes(alive_) + bytes(id_of_slot_) + bytes(slot_of_id_) +
             bytes(free_slots_) + bytes(nbr_begin_) + bytes(nbr_end_) + bytes(nbr_cap_) + bytes(nbr_) +
             bytes(hist_) + bytes(touching_) + bytes(cell_start_) + bytes(added_since_build_) + bytes(slab_of_) +
             bytes(slab_start_) + bytes(wall_hist_) + bytes(wall_touching_) + bytes(particle_tri_start_) +
             bytes(particle_tris_) + bytes(wall_chunk_);
  for (const auto& a : slab_added_) b += bytes(a);
  return b;
}

Vector3d DemSystem::Momentum() const {
  Vector3d p = Vector3d::Zero();
  for (size_t i = 0; i < x_.size(); ++i)
    if (alive_[i]) p += mass_ * v_[i];
  return p;
}

}  // namespace dem_mobility
