#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/common/state_archive.h"

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

int ParticleStore::LiveSlot(int id) const {
  DM_THROW_UNLESS(id >= 0 && id < size() && alive(id), "particle ", id, " is not a live particle");
  return ids_[id].slot;
}

int ParticleStore::Add(const Eigen::Vector3d& x0, const Eigen::Vector3d& v0, const Eigen::Vector3d& f0,
                       double adhesion0, SlotState st, bool* appended) {
  const int id = size();
  int p;
  *appended = free_slots_.empty();
  if (!*appended) {  // the lowest free slot
    p = free_slots_.front();
    free_slots_.erase(free_slots_.begin());
    const int old_id = id_of_slot[p];  // the removed particle's last state is gone now
    if (old_id != kNoId) ids_[old_id] = IdRecord{IdRecord::State::kGone, -1};
  } else {
    p = slots();
    x.emplace_back();
    v.emplace_back();
    f.emplace_back();
    x_built.emplace_back();
    plastic.push_back(0.0);
    adhesion_max.push_back(0.0);
    max_repulsion.push_back(0.0);
    normal_sum.push_back(0.0);
    adhesion_reach.push_back(0.0);
    contacts.push_back(0.0);
    overlap.push_back(0.0);
    state.push_back(SlotState::kFree);
    held.push_back(0);
    id_of_slot.push_back(kNoId);
  }
  ids_.push_back(IdRecord{IdRecord::State::kLive, p});
  id_of_slot[p] = id;
  x[p] = x0;
  v[p] = v0;
  f[p] = f0;
  x_built[p] = x0;
  plastic[p] = 0.0;
  adhesion_max[p] = adhesion0;
  max_repulsion[p] = normal_sum[p] = adhesion_reach[p] = contacts[p] = overlap[p] = 0.0;
  state[p] = st;
  held[p] = 0;
  return id;
}

int ParticleStore::Remove(int id) {
  const int i = ids_[id].slot;
  state[i] = SlotState::kFree;
  held[i] = 0;
  f[i].setZero();
  max_repulsion[i] = normal_sum[i] = adhesion_reach[i] = contacts[i] = overlap[i] = 0.0;
  ids_[id].state = IdRecord::State::kRemoved;
  ++removed_;
  free_slots_.insert(std::lower_bound(free_slots_.begin(), free_slots_.end(), i), i);
  return i;
}

void ParticleStore::Permute(const std::vector<int>& order) {
  PermuteSlots(&x, order, 1);
  PermuteSlots(&v, order, 1);
  PermuteSlots(&f, order, 1);
  PermuteSlots(&plastic, order, 1);
  PermuteSlots(&adhesion_max, order, 1);
  PermuteSlots(&max_repulsion, order, 1);
  PermuteSlots(&normal_sum, order, 1);
  PermuteSlots(&adhesion_reach, order, 1);
  PermuteSlots(&contacts, order, 1);
  PermuteSlots(&overlap, order, 1);
  PermuteSlots(&state, order, 1);
  PermuteSlots(&held, order, 1);
  PermuteSlots(&id_of_slot, order, 1);
  free_slots_.clear();
  for (int s = 0; s < slots(); ++s) {
    if (live(s)) {
      ids_[id_of_slot[s]] = IdRecord{IdRecord::State::kLive, s};
    } else {
      free_slots_.push_back(s);
      if (id_of_slot[s] != kNoId) ids_[id_of_slot[s]] = IdRecord{IdRecord::State::kRemoved, s};
    }
  }
}

size_t ParticleStore::MemoryBytes() const {
  auto bytes = [](const auto& a) { return a.capacity() * sizeof(a[0]); };
  return bytes(x) + bytes(v) + bytes(f) + bytes(x_built) + bytes(plastic) + bytes(adhesion_max) +
         bytes(max_repulsion) + bytes(normal_sum) + bytes(adhesion_reach) + bytes(contacts) + bytes(overlap) + bytes(state) + bytes(held) + bytes(id_of_slot) + bytes(hot) + bytes(sums) +
         bytes(ids_) + bytes(free_slots_);
}

template <class Ar>
void ParticleStore::Io(Ar& ar) {
  ar.Tag("particles");
  // (not `hot` nor `sums`: the pair kernels' scratch, packed from these arrays before every sweep)
  ar(x, v, f, x_built, plastic, adhesion_max, max_repulsion, normal_sum, adhesion_reach, contacts, overlap, state, held, id_of_slot, ids_,
     free_slots_, removed_);
  if constexpr (Ar::kLoading) {
    hot.clear();
    sums.clear();
    const size_t n = x.size();
    for (size_t len : {v.size(), f.size(), x_built.size(), plastic.size(), adhesion_max.size(), max_repulsion.size(),
                       normal_sum.size(), adhesion_reach.size(), contacts.size(), overlap.size(), state.size(), held.size(), id_of_slot.size()})
      if (len != n) ar.Fail("the particle arrays differ in length");
    const int slots = static_cast<int>(n), ids = static_cast<int>(ids_.size());
    for (const IdRecord& r : ids_)
      if (r.state > IdRecord::State::kGone || r.slot >= slots || (r.state == IdRecord::State::kLive && r.slot < 0))
        ar.Fail("a particle's record lies beyond the slots");
    for (size_t s = 0; s < n; ++s)
      if (id_of_slot[s] < kNoId || id_of_slot[s] >= ids || state[s] > SlotState::kAdded)
        ar.Fail("a slot's particle is not one");
    for (int s : free_slots_)
      if (s < 0 || s >= slots) ar.Fail("a free slot lies beyond the slots");
    if (removed_ < 0 || removed_ > ids) ar.Fail("the count of removed particles is not one");
  }
}
template void ParticleStore::Io(StateWriter&);
template void ParticleStore::Io(StateReader&);

}  // namespace dem_mobility::core
