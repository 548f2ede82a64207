// The DEM particles' storage: per-slot arrays (structure of arrays, as the solver's loops read
// them), the stable IDs the caller sees, and the free slots. Slots are permuted at every neighbour
// build (sorted by slab and cell); IDs never change and are never reused.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <vector>

#include "dem_mobility/core/common/huge_pages.h"

namespace dem_mobility::core {

/// What a slot holds.
enum class SlotState : unsigned char {
  kFree,    ///< nothing (never used, or its particle was removed)
  kListed,  ///< a particle the last neighbour build listed
  kAdded,   ///< a particle added since the last neighbour build
};

/// Where the particle with a given ID is.
struct IdRecord {
  using StateBulk = void;
  enum class State : unsigned char {
    kLive,     ///< in `slot`
    kRemoved,  ///< removed; `slot` still holds its last state (until the slot is reused)
    kGone,     ///< removed and its slot reused: no state left
  };
  State state = State::kGone;
  int slot = -1;
};

/// What the pair sweep reads of a partner, packed into one cache line (written before each sweep
/// from the per-slot arrays below; the vector kernels gather from it).
struct alignas(64) HotParticle {
  using StateBulk = void;
  double x[3], v[3];
  double plastic, adhesion_max;
};
static_assert(sizeof(HotParticle) == 64, "one cache line");

/// What the pair sweep adds to a partner, in one cache line: the vector kernels sum into it
/// (copied from f, the plastic drive's sums and overlap before each sweep and back after it), so
/// that a partner's results cost one line and not five.
struct alignas(64) PairSums {
  double f[3];
  double max_repulsion, normal_sum, adhesion_reach, contacts, overlap;
};
static_assert(sizeof(PairSums) == 64, "one cache line");

class ParticleStore {
 public:
  static constexpr int kNoId = -1;

  // per slot (read and written directly by the solver's loops)
  std::vector<Eigen::Vector3d> x, v, f;
  std::vector<Eigen::Vector3d> x_built;  ///< position at the last neighbour build (or at its addition)
  std::vector<double> plastic;           ///< plastic deformation [m]
  std::vector<double> adhesion_max;      ///< maximum adhesion force [N]
  // of the slot's contacts at the last force evaluation: the largest repulsion, the sum of their
  // elastic normal forces, the sum of the reach of those whose adhesion is the slot's own, their
  // number (the plastic update's PlasticDrive, soil_law.h) and the largest overlap
  std::vector<double> max_repulsion, normal_sum, adhesion_reach, contacts, overlap;
  std::vector<SlotState> state;
  /// 1: held in place (zero velocity, not integrated; its contacts still act on its neighbours)
  std::vector<unsigned char> held;
  std::vector<int> id_of_slot;  ///< the ID whose (last) state the slot holds, or kNoId
  /// x, v, plastic and adhesion_max of every slot, packed before each force evaluation (the vector
  /// pair kernels gather from it; a scratch copy, never the state)
  std::vector<HotParticle> hot;
  /// f, max_repulsion, normal_sum, adhesion_reach, contacts and overlap of every slot while the forces are summed: the pair
  /// kernels and the walls add into it, and it is unpacked into those arrays afterwards (scratch
  /// as `hot` is)
  std::vector<PairSums> sums;

  int slots() const { return static_cast<int>(x.size()); }
  /// Sizes `hot` and `sums` to the slots (on huge pages when new).
  void SizeScratch() {
    const size_t n = x.size();
    if (hot.size() == n && sums.size() == n) return;
    ReserveOnHugePages(&hot, n);
    ReserveOnHugePages(&sums, n);
    hot.resize(n);
    sums.resize(n);
  }
  /// Packs slot s's hot record for a sweep, from x, v, plastic and adhesion_max.
  void PackHot(int s) {
    HotParticle& h = hot[s];
    h.x[0] = x[s].x();
    h.x[1] = x[s].y();
    h.x[2] = x[s].z();
    h.v[0] = v[s].x();
    h.v[1] = v[s].y();
    h.v[2] = v[s].z();
    h.plastic = plastic[s];
    h.adhesion_max = adhesion_max[s];
  }
  /// Starts slot s's sums for a force evaluation: force `f0` (a live slot's weight, or zero), zero
  /// maxima.
  void StartSums(int s, const Eigen::Vector3d& f0) {
    PairSums& r = sums[s];
    r.f[0] = f0.x();
    r.f[1] = f0.y();
    r.f[2] = f0.z();
    r.max_repulsion = r.normal_sum = r.adhesion_reach = r.contacts = r.overlap = 0.0;
  }
  /// Packs slot s for a sweep: its hot record and its sums started at `f0`.
  void PackFresh(int s, const Eigen::Vector3d& f0) {
    PackHot(s);
    StartSums(s, f0);
  }
  /// Slot s's sums back into f, max_repulsion, normal_sum, adhesion_reach, contacts and overlap.
  void Unpack(int s) {
    const PairSums& r = sums[s];
    f[s] = Eigen::Vector3d(r.f[0], r.f[1], r.f[2]);
    max_repulsion[s] = r.max_repulsion;
    normal_sum[s] = r.normal_sum;
    adhesion_reach[s] = r.adhesion_reach;
    contacts[s] = r.contacts;
    overlap[s] = r.overlap;
  }
  bool live(int s) const { return state[s] != SlotState::kFree; }
  /// IDs handed out so far (removed particles included).
  int size() const { return static_cast<int>(ids_.size()); }
  int num_alive() const { return size() - removed_; }
  bool alive(int id) const { return ids_[id].state == IdRecord::State::kLive; }
  const IdRecord& record(int id) const { return ids_.at(id); }
  /// The slot of a live particle; ConfigError otherwise.
  int LiveSlot(int id) const;

  /// A new ID in the lowest free slot, or in a slot appended at the end (`*appended` says which);
  /// the slot's state is reset (no plastic deformation, the given adhesion, zero maxima).
  int Add(const Eigen::Vector3d& x0, const Eigen::Vector3d& v0, const Eigen::Vector3d& f0, double adhesion0,
          SlotState st, bool* appended);
  /// Frees the live particle's slot; its last state stays readable by ID until the slot is reused.
  /// Returns the slot.
  int Remove(int id);
  /// New slot s takes old slot order[s] (x_built is not moved: a build sets it afterwards); the
  /// ID records and the free slots follow.
  void Permute(const std::vector<int>& order);

  /// The value of a per-slot array for an ID (a removed particle: its last state; gone: NaN).
  template <class T>
  T Get(const std::vector<T>& a, int id) const {
    const IdRecord& r = ids_.at(id);
    if (r.state == IdRecord::State::kGone) return NaNLike(T());
    return a[r.slot];
  }
  size_t MemoryBytes() const;
  /// Its state in a checkpoint (common/state_archive.h): every array and the ID records.
  template <class Ar>
  void Io(Ar& ar);

 private:
  static double NaNLike(double) { return std::numeric_limits<double>::quiet_NaN(); }
  static Eigen::Vector3d NaNLike(const Eigen::Vector3d&) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }

  std::vector<IdRecord> ids_;
  std::vector<int> free_slots_;  ///< ascending
  int removed_ = 0;
};

}  // namespace dem_mobility::core
