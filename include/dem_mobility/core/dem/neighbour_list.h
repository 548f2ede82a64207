// The DEM neighbour lists: a Cartesian cell grid one cutoff wide, slabs of whole cells along the
// longest axis, and half lists (each pair listed once, by its owner) carrying each contact's
// tangential history.
//
// Ownership and slabs: a pair belongs to the particle in the lower slab (or, in the same slab, the
// lower slot), so a slab's pairs write only to its own and the next slab's particles; the pair
// sweep runs the even slabs in parallel, then the odd ones (each odd slab once the even slabs beside
// it are done: pair_sweep.cpp's SweepSlabs). Slabs are at least one cutoff thick and depend on the
// particles only, not on the thread count.
//
// A build sorts the particle slots by slab and cell (returns the permutation, for other per-slot
// data) and lists each live slot's partners within the cutoff, ascending, with `list_slack` spare
// entries; histories of contacts that survive are carried over. Between builds a particle can be
// inserted (its neighbours found in the last build's grid, at their positions at the build, which
// keeps the Verlet-skin guarantee) and removed, without a build.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

class NeighbourList {
 public:
  NeighbourList(double cutoff, int list_slack) : cutoff_(cutoff), slack_(list_slack) {}

  /// Sorts the store's slots (returns order: new slot s holds old slot order[s]), lists all
  /// pairs, marks every live slot listed and sets x_built to x.
  std::vector<int> Build(ParticleStore* ps, int threads);
  /// A slot appended to the store after the first build: an empty list.
  void AppendSlot();
  /// Lists the pairs of slot p, added since the build. False when a neighbour's list had no room
  /// left: the lists are then incomplete until the next Build.
  bool Insert(const ParticleStore& ps, int p);
  /// Takes live slot i's pairs out of the lists (before the store frees it).
  void Remove(const ParticleStore& ps, int i);
  /// The slots of the last build in the 27 cells about x, and those added since.
  std::vector<int> Candidates(const ParticleStore& ps, const Eigen::Vector3d& x) const;

  // the half list of slot i: partners in partners()[begin(i), end(i)), ascending, with the
  // contact's history (from i's side) and whether it touched at the last force evaluation
  int begin(int i) const { return nbr_begin_[i]; }
  int end(int i) const { return nbr_end_[i]; }
  const std::vector<int>& list_begin() const { return nbr_begin_; }
  const std::vector<int>& list_end() const { return nbr_end_; }
  const std::vector<int>& partners() const { return nbr_; }
  std::vector<TangentialHistory>& histories() { return hist_; }
  const std::vector<TangentialHistory>& histories() const { return hist_; }
  std::vector<unsigned char>& touching() { return touching_; }
  const std::vector<unsigned char>& touching() const { return touching_; }
  // the slabs: slots of the build in [slab_start(s), slab_start(s + 1)), those added since in slab_added(s)
  int num_slabs() const { return static_cast<int>(slab_added_.size()); }
  int slab_start(int s) const { return slab_start_[s]; }
  const std::vector<int>& slab_added(int s) const { return slab_added_[s]; }

  int contacts() const;  ///< pairs touching at the last force evaluation
  size_t MemoryBytes() const;
  /// Its state in a checkpoint (common/state_archive.h): the lists, their histories, the build's
  /// grid and slabs (a restart goes on with the lists it had, not with a new build).
  template <class Ar>
  void Io(Ar& ar);

 private:
  Eigen::Vector3i CellOf(const Eigen::Vector3d& x) const;
  long CellIndex(const Eigen::Vector3i& c) const { return c.cast<long>().dot(grid_stride_); }
  int SlabOfCell(const Eigen::Vector3i& c) const {
    return std::min(c[slab_axis_] / cells_per_slab_, static_cast<int>(slab_start_.size()) - 2);
  }
  bool Owns(int i, int j) const { return slab_of_[i] < slab_of_[j] || (slab_of_[i] == slab_of_[j] && i < j); }
  /// Calls f(cell index) for each of the 27 cells about cell c that lie in the grid.
  template <class F>
  void ForEachCellNear(const Eigen::Vector3i& c, F&& f) const {
    Eigen::Vector3i q;
    for (q.z() = c.z() - 1; q.z() <= c.z() + 1; ++q.z())
      for (q.y() = c.y() - 1; q.y() <= c.y() + 1; ++q.y())
        for (q.x() = c.x() - 1; q.x() <= c.x() + 1; ++q.x()) {
          if ((q.array() < 0).any() || (q.array() >= grid_dims_.array()).any()) continue;
          f(CellIndex(q));
        }
  }
  /// Calls f(slot) for every slot the last build put in the 27 cells about cell c.
  template <class F>
  void ForEachSlotNear(const Eigen::Vector3i& c, F&& f) const {
    ForEachCellNear(c, [&](long cell) {
      for (int j = cell_start_[cell]; j < cell_start_[cell + 1]; ++j) f(j);
    });
  }
  std::vector<long> SetUpGrid(const ParticleStore& ps);
  std::vector<int> SortSlots(ParticleStore* ps, const std::vector<long>& cell);
  void SetUpSlabs(int n);
  void ListPairs(const ParticleStore& ps, int threads);
  const TangentialHistory* FindHistory(int i, int j) const;
  bool InsertPair(int i, int j);
  void RemovePair(int i, int j);

  double cutoff_;
  int slack_;
  // the half lists: slot i's in nbr_[nbr_begin_[i], nbr_end_[i]), with room up to nbr_cap_[i]
  std::vector<int> nbr_begin_, nbr_end_, nbr_cap_, nbr_;
  std::vector<TangentialHistory> hist_;
  std::vector<unsigned char> touching_;
  // the last build's cell grid (the slots of cell c are cell_start_[c] .. cell_start_[c + 1] - 1,
  // at their positions at the build); the slab axis is the slowest-varying one
  Eigen::Vector3d grid_lo_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i grid_dims_ = Eigen::Vector3i::Ones();
  Eigen::Matrix<long, 3, 1> grid_stride_ = Eigen::Matrix<long, 3, 1>::Ones();
  std::vector<int> cell_start_, added_since_build_;
  // slabs: cells_per_slab_ cells (each at least one cutoff) along slab_axis_
  int slab_axis_ = 0, cells_per_slab_ = 1;
  std::vector<int> slab_of_, slab_start_;
  std::vector<std::vector<int>> slab_added_;
  std::vector<std::vector<int>> found_;  ///< a build's partners, per thread (kept: no allocation per slot)
};

}  // namespace dem_mobility::core
