#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/common/state_archive.h"

#include <algorithm>
#include <cmath>
#include <omp.h>

namespace dem_mobility::core {

using Eigen::Vector3d;

Eigen::Vector3i NeighbourList::CellOf(const Vector3d& x) const {
  // clamped: a particle outside the grid's box lands in a border cell, whose neighbour cells
  // still hold every particle within one cell width of it
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const double u = std::floor((x[a] - grid_lo_[a]) / cutoff_);
    c[a] = u < 0.0 ? 0 : u >= grid_dims_[a] - 1 ? grid_dims_[a] - 1 : static_cast<int>(u);
  }
  return c;
}

std::vector<int> NeighbourList::Candidates(const ParticleStore& ps, const Vector3d& x) const {
  std::vector<int> out;
  ForEachSlotNear(CellOf(x), [&](int j) {
    if (ps.state[j] == SlotState::kListed) out.push_back(j);
  });
  for (int j : added_since_build_)
    if (ps.state[j] == SlotState::kAdded) out.push_back(j);
  return out;
}

std::vector<long> NeighbourList::SetUpGrid(const ParticleStore& ps) {
  // a uniform grid of cells one cutoff wide over the live particles' bounding box; the longest
  // axis is the slab axis, made the slowest-varying one of the cell index. Returns each slot's
  // cell (-1: free) and counts the slots per cell into cell_start_.
  const int n = ps.slots();
  Vector3d lo = Vector3d::Constant(1e300), hi = -lo;
  for (int i = 0; i < n; ++i)
    if (ps.live(i)) {
      lo = lo.cwiseMin(ps.x[i]);
      hi = hi.cwiseMax(ps.x[i]);
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
  std::vector<long> cell(n, -1);
  cell_start_.assign(ncell + 1, 0);
  for (int i = 0; i < n; ++i)
    if (ps.live(i)) {
      cell[i] = CellIndex(CellOf(ps.x[i]));
      ++cell_start_[cell[i] + 1];
    }
  for (long c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  return cell;
}

std::vector<int> NeighbourList::SortSlots(ParticleStore* ps, const std::vector<long>& cell) {
  // a stable counting sort of the live slots by cell (slab-major), the free slots last
  const int n = ps->slots();
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
  ps->Permute(order);
  // the old lists stay where they are, reached through the new slot numbers
  PermuteSlots(&nbr_begin_, order, 1);
  PermuteSlots(&nbr_end_, order, 1);
  std::vector<int> new_of_old(n);
  for (int s = 0; s < n; ++s) new_of_old[order[s]] = s;
  for (int& j : nbr_) j = j >= 0 ? new_of_old[j] : j;
  return order;
}

void NeighbourList::SetUpSlabs(int n) {
  // slabs of whole cells, at least one cutoff thick, at most 64
  const long ncell = static_cast<long>(cell_start_.size()) - 1;
  cells_per_slab_ = std::max(1, (grid_dims_[slab_axis_] + 63) / 64);
  const int ns = (grid_dims_[slab_axis_] + cells_per_slab_ - 1) / cells_per_slab_;
  slab_start_.assign(ns + 1, 0);
  Eigen::Vector3i c = Eigen::Vector3i::Zero();
  for (int s = 0; s < ns; ++s) {
    c[slab_axis_] = s * cells_per_slab_;
    slab_start_[s] = cell_start_[CellIndex(c)];
  }
  slab_start_[ns] = cell_start_[ncell];
  slab_of_.resize(n);
  for (int s = 0; s < ns; ++s)
    for (int i = slab_start_[s]; i < slab_start_[s + 1]; ++i) slab_of_[i] = s;
  slab_added_.assign(ns, {});
}

const TangentialHistory* NeighbourList::FindHistory(int i, int j) const {
  for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k)
    if (nbr_[k] == j) return touching_[k] ? &hist_[k] : nullptr;
  return nullptr;
}

void NeighbourList::ListPairs(const ParticleStore& ps, int threads) {
  // each slot's partners within the cutoff in the pairs it owns (half list), ascending. Each thread
  // takes a contiguous range of slots and lists their partners one after the other in a buffer of
  // its own (kept from build to build: no allocation per slot), then, once every slot's count is
  // known, copies them to their place: the same lists for any thread count. The surviving
  // contacts' histories are first copied out of the old lists (per thread), then every thread
  // writes its own range of the new ones in place of the old: nothing is filled twice, and nothing
  // on one thread while the other waits.
  struct Carried {
    Vector3d spring;
    bool touching;
  };
  const int n = ps.slots();
  const double cut2 = cutoff_ * cutoff_;
  const int live = cell_start_.back();
  const std::vector<Vector3d>& x = ps.x;
  if (static_cast<int>(found_.size()) < threads) found_.resize(threads);
  std::vector<std::vector<Carried>> carried(threads);
  std::vector<int> begin(n), end(n), cap(n);
  int total = 0;
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const int lo = static_cast<int>(static_cast<long>(live) * t / nt);
    const int hi = static_cast<int>(static_cast<long>(live) * (t + 1) / nt);
    std::vector<int>& out = found_[t];
    size_t used = 0;  // out's entries in use (out is grown ahead of them)
    // slots [j0, j1) within the cutoff of slot i, appended: each candidate is written, and kept by
    // counting it, without a branch on the distance (about half the candidates are in reach: a
    // branch on it was mispredicted every other time)
    auto scan = [&](int i, int j0, int j1) {
      if (j1 <= j0) return;
      if (out.size() < used + static_cast<size_t>(j1 - j0)) out.resize(2 * (used + static_cast<size_t>(j1 - j0)));
      int* o = out.data();
      const Vector3d xi = x[i];
      for (int j = j0; j < j1; ++j) {
        o[used] = j;
        used += (xi - x[j]).squaredNorm() < cut2;
      }
    };
    const int a1 = (slab_axis_ + 1) % 3, a2 = (slab_axis_ + 2) % 3, s = slab_axis_;
    // the cell of slot i: the live slots are sorted by cell, so the cells are walked along with
    // the slots (cell_start_), each cell's coordinates worked out once, instead of from each slot's
    // position (CellOf: the same cell, from the same position, as SetUpGrid sorted it by)
    long cell = std::upper_bound(cell_start_.begin(), cell_start_.end(), lo) - cell_start_.begin() - 1;
    Eigen::Vector3i c(0, 0, 0);
    long c_of = -1;  // the cell c holds the coordinates of
    for (int i = lo; i < hi; ++i) {
      const size_t first = used;
      // the live slots are in cell order (slab-major: SortSlots), so Owns(i, j) is i < j here: the
      // cells before i's own hold lower slots only, those after it higher ones only. The cells
      // along axis a1 (stride 1) are consecutive, and so are their slots: of the 27 cells, the
      // rest of i's own row of three (its own cell from i + 1 on) and the four whole rows after it
      // ((a2 + 1, s) and (a2 - 1..a2 + 1, s + 1)), in that order: ascending slots, so the list
      // comes out sorted (the same lists as a look at every cell and a sort)
      while (cell_start_[cell + 1] <= i) ++cell;
      if (cell != c_of) {
        c_of = cell;
        c[s] = static_cast<int>(cell / grid_stride_[s]);
        const long in_slab = cell % grid_stride_[s];
        c[a2] = static_cast<int>(in_slab / grid_stride_[a2]);
        c[a1] = static_cast<int>(in_slab % grid_stride_[a2]);
      }
      const int r0 = std::max(c[a1] - 1, 0), r1 = std::min(c[a1] + 1, grid_dims_[a1] - 1);
      auto row_end = [&](int q2, int qs) {
        return cell_start_[r1 + 1 + q2 * grid_stride_[a2] + static_cast<long>(qs) * grid_stride_[s]];
      };
      auto row_begin = [&](int q2, int qs) {
        return cell_start_[r0 + q2 * grid_stride_[a2] + static_cast<long>(qs) * grid_stride_[s]];
      };
      scan(i, i + 1, row_end(c[a2], c[s]));
      if (c[a2] + 1 < grid_dims_[a2]) scan(i, row_begin(c[a2] + 1, c[s]), row_end(c[a2] + 1, c[s]));
      if (c[s] + 1 < grid_dims_[s])
        for (int q2 = std::max(c[a2] - 1, 0); q2 <= std::min(c[a2] + 1, grid_dims_[a2] - 1); ++q2)
          scan(i, row_begin(q2, c[s] + 1), row_end(q2, c[s] + 1));
      end[i] = static_cast<int>(used - first);  // the count, for now
    }
    // carry each surviving contact's history over, from whichever side owned it before
    std::vector<Carried>& mine = carried[t];
    ReserveOnHugePages(&mine, used);  // (see huge_pages.h)
    size_t m = 0;
    for (int i = lo; i < hi; ++i)
      for (int c = 0; c < end[i]; ++c, ++m) {
        const int j = out[m];
        if (const TangentialHistory* h = FindHistory(i, j))
          mine.push_back(Carried{h->spring, true});
        else if (const TangentialHistory* g = FindHistory(j, i))
          mine.push_back(Carried{-g->spring, true});
        else
          mine.push_back(Carried{Vector3d::Zero(), false});
      }
#pragma omp barrier
#pragma omp single
    {
      // the lists in slot order, each with room for slack_ more; in the old lists' place (grown
      // without copying them when they are too small: they are not read any more; with a sixteenth
      // to spare, so that a bed being pressed together, its pairs growing a little at each build,
      // does not take fresh pages at every build)
      for (int i = 0; i < n; ++i) {
        const int count = i < live ? end[i] : 0;
        begin[i] = total;
        end[i] = total + count;
        cap[i] = i < live ? end[i] + slack_ : end[i];
        total = cap[i];
      }
      if (static_cast<size_t>(total) > nbr_.capacity() || static_cast<size_t>(total) > hist_.capacity() ||
          static_cast<size_t>(total) > touching_.capacity()) {
        nbr_ = std::vector<int>();
        hist_ = std::vector<TangentialHistory>();
        touching_ = std::vector<unsigned char>();
        const size_t room = static_cast<size_t>(total) + static_cast<size_t>(total) / 16;
        ReserveOnHugePages(&nbr_, room);
        ReserveOnHugePages(&hist_, room);
        ReserveOnHugePages(&touching_, room);
      }
      nbr_.resize(total);
      hist_.resize(total);
      touching_.resize(total);
    }
    // this thread's slots' lists, slack included: [begin[lo], cap[hi - 1])
    m = 0;
    for (int i = lo; i < hi; ++i) {
      for (int k = begin[i]; k < end[i]; ++k, ++m) {
        nbr_[k] = out[m];
        hist_[k].spring = mine[m].spring;
        touching_[k] = mine[m].touching ? 1 : 0;
      }
      for (int k = end[i]; k < cap[i]; ++k) {
        nbr_[k] = -1;
        hist_[k] = TangentialHistory();
        touching_[k] = 0;
      }
    }
  }
  nbr_begin_.swap(begin);
  nbr_end_.swap(end);
  nbr_cap_.swap(cap);
}

std::vector<int> NeighbourList::Build(ParticleStore* ps, int threads) {
  const int n = ps->slots();
  const std::vector<long> cell = SetUpGrid(*ps);
  // the old lists (valid once built) are carried through the sort for the contact histories
  if (static_cast<int>(nbr_begin_.size()) != n) {
    nbr_begin_.assign(n, 0);
    nbr_end_.assign(n, 0);
    nbr_.clear();
  }
  std::vector<int> order = SortSlots(ps, cell);
  SetUpSlabs(n);
  ListPairs(*ps, threads);
  for (int i = 0; i < n; ++i) {
    ps->x_built[i] = ps->x[i];
    if (ps->live(i)) ps->state[i] = SlotState::kListed;
  }
  added_since_build_.clear();
  return order;
}

void NeighbourList::AppendSlot() {
  nbr_begin_.push_back(static_cast<int>(nbr_.size()));
  nbr_end_.push_back(nbr_begin_.back());
  nbr_cap_.push_back(nbr_begin_.back());
  slab_of_.push_back(0);
}

bool NeighbourList::Insert(const ParticleStore& ps, int p) {
  // its neighbours at their positions at the last build (or at their addition): as in a build,
  // so the skin guarantee holds for the new pairs. Its slab from where it is: within a cutoff of
  // its neighbours' positions, so at most one slab from theirs.
  const double cut2 = cutoff_ * cutoff_;
  const Vector3d& xp = ps.x[p];
  added_since_build_.push_back(p);
  slab_of_[p] = SlabOfCell(CellOf(xp));
  slab_added_[slab_of_[p]].push_back(p);
  std::vector<int> found;
  for (int j : Candidates(ps, xp))
    if (j != p && (ps.x_built[j] - xp).squaredNorm() < cut2) found.push_back(j);
  std::sort(found.begin(), found.end());
  // the pairs it owns in a list of its own at the end of the pool, with room to spare
  std::vector<int> own;
  for (int j : found)
    if (Owns(p, j)) own.push_back(j);
  nbr_begin_[p] = static_cast<int>(nbr_.size());
  nbr_end_[p] = nbr_begin_[p] + static_cast<int>(own.size());
  nbr_cap_[p] = nbr_end_[p] + slack_;
  nbr_.insert(nbr_.end(), own.begin(), own.end());
  nbr_.resize(nbr_cap_[p], -1);
  hist_.resize(nbr_cap_[p]);
  touching_.resize(nbr_cap_[p], 0);
  for (int k = nbr_begin_[p]; k < nbr_cap_[p]; ++k) {
    hist_[k] = TangentialHistory();
    touching_[k] = 0;
  }
  for (int j : found)
    if (!Owns(p, j) && !InsertPair(j, p)) return false;
  return true;
}

bool NeighbourList::InsertPair(int i, int j) {
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

void NeighbourList::Remove(const ParticleStore& ps, int i) {
  // its pairs: those it owns, and those its neighbours own
  nbr_end_[i] = nbr_begin_[i];
  for (int j : Candidates(ps, ps.x_built[i]))
    if (j != i && Owns(j, i)) RemovePair(j, i);
  if (ps.state[i] == SlotState::kAdded) {
    std::vector<int>& added = slab_added_[slab_of_[i]];
    added.erase(std::find(added.begin(), added.end(), i));
  }
}

void NeighbourList::RemovePair(int i, int j) {
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

int NeighbourList::contacts() const {
  int c = 0;
  for (size_t i = 0; i < nbr_begin_.size(); ++i)
    for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k) c += touching_[k];
  return c;
}

size_t NeighbourList::MemoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  size_t b = bytes(nbr_begin_) + bytes(nbr_end_) + bytes(nbr_cap_) + bytes(nbr_) + bytes(hist_) + bytes(touching_) +
             bytes(cell_start_) + bytes(added_since_build_) + bytes(slab_of_) + bytes(slab_start_);
  for (const auto& a : slab_added_) b += bytes(a);
  for (const auto& a : found_) b += bytes(a);
  return b;
}

template <class Ar>
void NeighbourList::Io(Ar& ar) {
  ar.Tag("neighbour_lists");
  ar(nbr_begin_, nbr_end_, nbr_cap_, nbr_, hist_, touching_, grid_lo_, grid_dims_, grid_stride_, cell_start_,
     added_since_build_, slab_axis_, cells_per_slab_, slab_of_, slab_start_, slab_added_);
  if constexpr (Ar::kLoading) {
    if (nbr_.size() != hist_.size() || nbr_.size() != touching_.size()) ar.Fail("the pair lists differ in length");
    if (nbr_begin_.size() != nbr_end_.size() || nbr_begin_.size() != nbr_cap_.size())
      ar.Fail("the list bounds differ in length");
    const int n = static_cast<int>(nbr_begin_.size());
    for (int i = 0; i < n; ++i) {
      if (nbr_begin_[i] < 0 || nbr_begin_[i] > nbr_end_[i] || nbr_end_[i] > nbr_cap_[i] ||
          nbr_cap_[i] > static_cast<int>(nbr_.size()))
        ar.Fail("a list's bounds lie outside the pairs");
      for (int k = nbr_begin_[i]; k < nbr_end_[i]; ++k)
        if (nbr_[k] < 0 || nbr_[k] >= n) ar.Fail("a listed partner lies beyond the slots");
    }
    if ((grid_dims_.array() < 1).any() ||
        static_cast<long>(cell_start_.size()) != static_cast<long>(grid_dims_.cast<long>().prod()) + 1)
      ar.Fail("the cell grid does not match its cells");
    for (size_t c = 0; c < cell_start_.size(); ++c)
      if (cell_start_[c] < 0 || cell_start_[c] > n || (c > 0 && cell_start_[c] < cell_start_[c - 1]))
        ar.Fail("a cell's slots lie beyond the slots");
    if (slab_axis_ < 0 || slab_axis_ > 2 || cells_per_slab_ < 1 || slab_start_.size() < 2 ||
        slab_added_.size() + 1 != slab_start_.size())
      ar.Fail("the slabs are not slabs");
    for (size_t s = 0; s < slab_start_.size(); ++s)
      if (slab_start_[s] < 0 || slab_start_[s] > n || (s > 0 && slab_start_[s] < slab_start_[s - 1]))
        ar.Fail("a slab's slots lie beyond the slots");
    const int slabs = static_cast<int>(slab_added_.size());
    if (static_cast<int>(slab_of_.size()) != n) ar.Fail("the slabs of the slots do not match the slots");
    for (int s : slab_of_)
      if (s < 0 || s >= slabs) ar.Fail("a slot's slab is not one");
    for (const auto& added : slab_added_)
      for (int i : added)
        if (i < 0 || i >= n) ar.Fail("a slab's added slot lies beyond the slots");
    for (int i : added_since_build_)
      if (i < 0 || i >= n) ar.Fail("an added slot lies beyond the slots");
  }
}
template void NeighbourList::Io(StateWriter&);
template void NeighbourList::Io(StateReader&);

}  // namespace dem_mobility::core
