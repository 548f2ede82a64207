#include "dem_mobility/core/dem/pair_sweep.h"

#include <algorithm>
#include <cmath>

namespace dem_mobility::core {

using Eigen::Vector3d;

void SweepPairs(const SoilContactLaw& law, double diameter, double dt, int threads, ParticleStore* ps,
                NeighbourList* lists) {
  const double D = diameter, D2 = D * D;
  std::vector<Vector3d>& x = ps->x;
  std::vector<Vector3d>& v = ps->v;
  std::vector<Vector3d>& f = ps->f;
  std::vector<double>& plastic = ps->plastic;
  std::vector<double>& adhesion_max = ps->adhesion_max;
  std::vector<double>& max_repulsion = ps->max_repulsion;
  std::vector<double>& max_tension = ps->max_tension;
  std::vector<double>& overlap_of = ps->overlap;
  const std::vector<int>& nbr_begin = lists->list_begin();
  const std::vector<int>& nbr_end = lists->list_end();
  const std::vector<int>& nbr = lists->partners();
  std::vector<TangentialHistory>& hist = lists->histories();
  std::vector<unsigned char>& touching = lists->touching();
  auto sweep = [&](int i) {
    const Vector3d xi = x[i], vi = v[i];
    const double pi = plastic[i], ai = adhesion_max[i];
    Vector3d fi = Vector3d::Zero();
    double max_rep = max_repulsion[i], max_ten = max_tension[i], max_overlap = overlap_of[i];
    for (int k = nbr_begin[i]; k < nbr_end[i]; ++k) {
      const int j = nbr[k];
      const Vector3d r = xi - x[j];
      const double r2 = r.squaredNorm();
      if (r2 >= D2) {  // in the skin, not touching
        if (touching[k]) {
          hist[k] = TangentialHistory();
          touching[k] = 0;
        }
        continue;
      }
      const double dist = std::sqrt(r2);
      const double overlap = D - dist;
      max_overlap = std::max(max_overlap, overlap);
      overlap_of[j] = std::max(overlap_of[j], overlap);
      // effective penetration: the overlap less both particles' plastic deformation
      const double d = overlap - (pi + plastic[j]);
      if (!(d > 0.0) || dist <= 0.0) {
        if (touching[k]) {
          hist[k] = TangentialHistory();
          touching[k] = 0;
        }
        continue;
      }
      const Vector3d nrm = r * (1.0 / dist);  // from j toward i
      const Vector3d vr = vi - v[j];
      const double vn = vr.dot(nrm);
      const SoilNormalForce fn = law.Normal(d, -vn, std::min(ai, adhesion_max[j]));
      const Vector3d vt = vr - vn * nrm;
      const Vector3d fc = fn.Total() * nrm + law.Tangential(nrm, vt, fn.repulsion, dt, &hist[k]);
      fi += fc;
      f[j] -= fc;
      max_rep = std::max(max_rep, fn.repulsion);
      max_ten = std::max(max_ten, -fn.adhesion);
      max_repulsion[j] = std::max(max_repulsion[j], fn.repulsion);
      max_tension[j] = std::max(max_tension[j], -fn.adhesion);
      touching[k] = 1;
    }
    f[i] += fi;
    max_repulsion[i] = max_rep;
    max_tension[i] = max_ten;
    overlap_of[i] = max_overlap;
  };
  const std::vector<SlotState>& state = ps->state;
  const int ns = lists->num_slabs();
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int sl = colour; sl < ns; sl += 2) {
      for (int i = lists->slab_start(sl); i < lists->slab_start(sl + 1); ++i)
        if (state[i] == SlotState::kListed) sweep(i);
      for (const int i : lists->slab_added(sl)) sweep(i);
    }
  }
}

}  // namespace dem_mobility::core
