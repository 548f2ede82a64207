// Large arrays on the kernel's transparent huge pages, where it offers them on request (Linux's
// THP "madvise" mode, Debian's default). A neighbour build allocates its new lists and permuted
// per-slot arrays afresh (tens of MB for 10^5 particles): on 4 KiB pages the first touch of each
// page was a page fault, and those faults were most of a build's serial time. On 2 MiB pages a
// build takes 512 times fewer faults, and the sweep's scattered gathers fewer TLB misses.
#pragma once

#include <cstddef>
#include <vector>

namespace dem_mobility::core {

/// Asks the kernel to back [p, p + bytes) with huge pages where whole 2 MiB pages fit in it, before
/// the range is first touched (a hint: nothing changes where the kernel declines).
void AdviseHugePages(void* p, size_t bytes);

/// Reserves room for n elements in an empty vector, on huge pages (as AdviseHugePages); a vector
/// that holds elements or has the room already is left as it is.
template <class T>
void ReserveOnHugePages(std::vector<T>* v, size_t n) {
  if (!v->empty() || v->capacity() >= n) return;
  v->reserve(n);
  AdviseHugePages(v->data(), v->capacity() * sizeof(T));
}

/// Permutes a per-slot array of `width` entries per slot: new slot s takes old slot order[s], for
/// s < order.size() (entries beyond stay). One pass: a gather into a new array on huge pages, which
/// then replaces the old one.
template <class T>
void PermuteSlots(std::vector<T>* v, const std::vector<int>& order, size_t width) {
  std::vector<T> out;
  ReserveOnHugePages(&out, v->size());
  // element by element (push_back within the room reserved: a store and a count; a range insert
  // per slot was a call into the library's general insert for every slot)
  const T* in = v->data();
  for (const int o : order)
    for (size_t k = 0; k < width; ++k) out.push_back(in[static_cast<size_t>(o) * width + k]);
  for (size_t k = order.size() * width; k < v->size(); ++k) out.push_back(in[k]);
  v->swap(out);
}

}  // namespace dem_mobility::core
