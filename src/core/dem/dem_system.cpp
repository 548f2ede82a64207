#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/common/state_archive.h"

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/dem/dem_watchdogs.h"
#include "dem_mobility/core/dem/pair_sweep.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

DemSystem::DemSystem(const SoilParams& soil, const DemSettings& settings)
    : soil_(soil),
      settings_(settings),
      law_(soil),
      lists_(soil.diameter * (1.0 + settings.skin), settings.list_slack),
      walls_(soil.diameter * (1.0 + settings.skin), soil.diameter, settings.wall_bins) {
  DM_THROW_UNLESS(settings.skin > 0.0 && settings.skin <= 1.0, "DEM skin ", settings.skin,
                  " (fraction of the diameter) must lie in (0, 1]");
  DM_THROW_UNLESS(settings.threads >= 1, "DEM threads ", settings.threads, " must be >= 1");
  DM_THROW_UNLESS(settings.max_overlap > 0.0 && settings.max_overlap < 1.0, "DEM max_overlap ",
                  settings.max_overlap, " must lie in (0, 1)");
  DM_THROW_UNLESS(settings.list_slack >= 0, "DEM list_slack ", settings.list_slack, " must be >= 0");
  DM_THROW_UNLESS(settings.serial_below >= 0, "DEM serial_below ", settings.serial_below, " must be >= 0");
  settings_.pair_kernel = ResolvePairKernel(settings.pair_kernel);
  mass_ = soil.Mass();
  cutoff_ = soil.diameter * (1.0 + settings.skin);
}

int DemSystem::AddWall(DemWall wall) {
  DM_THROW_UNLESS(!finalized_, "wall '", wall.name, "': walls are added before Finalize()");
  const int w = walls_.Add(std::move(wall), soil_, ps_.slots());
  rebuild_ = true;
  return w;
}

// ---------------------------------------------------------------------------------------------
// particles in and out

int DemSystem::AddParticle(const Vector3d& x, const Vector3d& v) {
  DM_THROW_UNLESS(x.allFinite() && v.allFinite(), "particle ", size(), ": position and velocity must be finite");
  bool appended = false;
  // its contacts act from its first force evaluation on; before Finalize the first build lists it
  const int id = ps_.Add(x, v, mass_ * gravity_, MaxAdhesionForce(soil_, 0.0),
                         finalized_ ? SlotState::kAdded : SlotState::kListed, &appended);
  const int p = ps_.record(id).slot;
  if (appended) {
    walls_.AppendSlot(finalized_);
    if (finalized_) lists_.AppendSlot();
  }
  walls_.ClearSlot(p);
  // its sums start at its weight (a slot appended: the next step sizes and starts them all)
  if (appended)
    sums_started_ = false;
  else if (sums_started_)
    ps_.StartSums(p, mass_ * gravity_);
  if (!finalized_) {
    rebuild_ = true;
    return id;
  }
  if (!lists_.Insert(ps_, p)) {  // no room left in a neighbour's list: rebuild all lists now
    ++overflow_builds_;
    Rebuild();
  }
  ledger_.exchanged += ParticleEnergy(EnergyTerms(), ps_, lists_, ps_.record(id).slot);  // (a rebuild moves it)
  return id;
}

void DemSystem::RemoveParticle(int id) {
  DM_THROW_UNLESS(id >= 0 && id < size() && alive(id), "RemoveParticle: ", id, " is not a particle");
  const int i = ps_.record(id).slot;
  if (finalized_) {
    ledger_.exchanged -= ParticleEnergy(EnergyTerms(), ps_, lists_, i);
    lists_.Remove(ps_, i);
    walls_.ClearSlot(i);
  }
  if (sums_started_) ps_.StartSums(i, Vector3d::Zero());  // (a free slot's sums are zero)
  ps_.Remove(id);
}

void DemSystem::set_plastic_deformation(int id, double dp) {
  DM_THROW_UNLESS(std::isfinite(dp) && dp >= 0.0, "particle ", id, ": plastic deformation ", dp, " must be finite and >= 0");
  const int i = ps_.LiveSlot(id);
  if (finalized_) ledger_.exchanged -= ParticleEnergy(EnergyTerms(), ps_, lists_, i);
  ps_.plastic[i] = dp;
  ps_.adhesion_max[i] = MaxAdhesionForce(soil_, dp);
  if (finalized_) ledger_.exchanged += ParticleEnergy(EnergyTerms(), ps_, lists_, i);
}

void DemSystem::set_held(int id, bool held) {
  const int i = ps_.LiveSlot(id);
  if (held && finalized_) ledger_.exchanged -= 0.5 * mass_ * ps_.v[i].squaredNorm();  // its kinetic energy taken out
  if (held) ps_.v[i].setZero();
  ps_.held[i] = held ? 1 : 0;
}

void DemSystem::set_threads(int threads) {
  DM_THROW_UNLESS(threads >= 1, "DEM threads ", threads, " must be >= 1");
  settings_.threads = threads;
}

void DemSystem::set_pair_kernel(PairKernel kernel) { settings_.pair_kernel = ResolvePairKernel(kernel); }

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
// time stepping

TimeStepLimit DemSystem::CriticalTimeStep() const {
  return DemCriticalTimeStep(soil_, mass_, settings_.max_coordination);
}

void DemSystem::Finalize(double dt) {
  const TimeStepLimit lim = CriticalTimeStep();
  DM_THROW_UNLESS(std::isfinite(dt) && dt > 0.0, "DEM time step ", dt, " s must be positive");
  DM_THROW_UNLESS(!settings_.check_time_step || dt <= lim.dt_crit, "DEM time step ", dt, " s is above the critical step ", lim.dt_crit, " s (",
                  lim.detail, "); use dt <= ", lim.dt_crit, " s");
  dt_ = dt;
  Rebuild();
  finalized_ = true;
  ComputeForces();
  ledger_.e0 = MechanicalEnergy(EnergyTerms(), ps_, lists_).Total();
  ledger_.wall_work = ledger_.exchanged = 0.0;
}

void DemSystem::set_gravity(const Vector3d& g) {
  // a change of gravity during a run changes the particles' potential energy: from outside
  if (finalized_)
    for (int i = 0; i < ps_.slots(); ++i)
      if (ps_.live(i)) ledger_.exchanged -= mass_ * (g - gravity_).dot(ps_.x[i]);
  gravity_ = g;
  sums_started_ = false;  // (they start at the weight)
}

void DemSystem::Rebuild() {
  const std::vector<int> order = lists_.Build(&ps_, Threads());
  walls_.PermuteSlots(order);
  walls_.Build(ps_, Threads(), 0.0);
  rebuild_ = false;
  sums_started_ = false;  // (the slots moved)
  ++builds_;
}

void DemSystem::SumForces(bool packed) {
  const int T = Threads();
  if (!packed) {
    const int n = ps_.slots();
    const Vector3d weight = mass_ * gravity_;
    ps_.SizeScratch();
#pragma omp parallel for schedule(static) num_threads(T)
    for (int i = 0; i < n; ++i) ps_.PackFresh(i, ps_.live(i) ? weight : Vector3d::Zero());
  }
  SweepPacked(law_, soil_.diameter, dt_, T, &ps_, &lists_, settings_.pair_kernel);
  ledger_.wall_power = walls_.Compute(&ps_, dt_, T);
}

void DemSystem::ComputeForces() {
  SumForces(false);
  const int n = ps_.slots();
#pragma omp parallel for schedule(static) num_threads(Threads())
  for (int i = 0; i < n; ++i) ps_.Unpack(i);
}

void DemSystem::Step() {
  DM_DEMAND(finalized_);
  const int n = ps_.slots();
  const double h = 0.5 * dt_, half_skin = 0.5 * settings_.skin * soil_.diameter;
  const double inv_m = 1.0 / mass_;
  std::vector<Vector3d>& x = ps_.x;
  std::vector<Vector3d>& v = ps_.v;
  const std::vector<Vector3d>& f = ps_.f;
  const Vector3d weight = mass_ * gravity_;
  double max_disp2 = 0.0;
  int tripped = n;  // the lowest slot a watchdog trips on
  // (bench/dem_step_bench.cpp's StreamingRate runs this pass and the last one alone, for the
  // roofline: what changes the arrays they read or write changes it too)
  // the drift, each slot then packed for the force evaluation (while it is in the cache: one
  // pass over the particles fewer; a neighbour build below permutes the slots and packs them again).
  // The sums were started by the last step's final pass unless something changed the slots since
  ps_.SizeScratch();
  const bool started = sums_started_;
  sums_started_ = false;
#pragma omp parallel for schedule(static) num_threads(Threads()) reduction(max : max_disp2) reduction(min : tripped)
  for (int i = 0; i < n; ++i) {
    if (!ps_.live(i)) {
      if (!started) ps_.PackFresh(i, Vector3d::Zero());
      continue;
    }
    if (!ps_.held[i]) {
      v[i] += h * inv_m * f[i];
      x[i] += dt_ * v[i];
      max_disp2 = std::max(max_disp2, (x[i] - ps_.x_built[i]).squaredNorm());
    }
    if (StateTrips(ps_, i, dt_, half_skin)) tripped = std::min(tripped, i);
    if (started)
      ps_.PackHot(i);
    else
      ps_.PackFresh(i, weight);
  }
  time_ += dt_;
  ++step_;
  if (tripped < n) ReportStateTrip(ps_, tripped, dt_, half_skin, step_, time_);
  walls_.UpdateVertices();  // the walls' poses were set for this step from outside
  bool packed = true;
  if (rebuild_ || max_disp2 > half_skin * half_skin || walls_.MaxWallDisplacement(false) > half_skin) {
    Rebuild();  // the particles or a slow wall moved half the skin
    packed = false;
  } else if (walls_.NeedsBuild(std::sqrt(max_disp2))) {  // a fast wall moved: only the wall candidates
    walls_.Build(ps_, Threads(), std::sqrt(max_disp2));
  }
  const double power_before = ledger_.wall_power;
  SumForces(packed);
  ledger_.wall_work += h * (power_before + ledger_.wall_power);  // trapezoidal
  const double overlap_limit = settings_.max_overlap * soil_.diameter;
  const bool ledger = plastic_ledger_;
  if (ledger && static_cast<int>(plastic_rec_.size()) < n) {
    plastic_rec_.resize(n);
    plastic_de_.resize(n);
  }
  // one pass: each slot's sums unpacked and started for the next step's force evaluation (the line
  // is in the cache now: the drift need not fetch it), the overlap watchdog, the second half kick
  // and the plastic update (a slot's sums and state read once; a trip is reported after the pass,
  // with the step's state complete)
  int changed = 0;
#pragma omp parallel for schedule(static) num_threads(Threads()) reduction(min : tripped) reduction(+ : changed)
  for (int i = 0; i < n; ++i) {
    ps_.Unpack(i);
    if (!ps_.live(i)) {
      ps_.StartSums(i, Vector3d::Zero());
      continue;
    }
    ps_.StartSums(i, weight);
    if (OverlapTrips(ps_, i, overlap_limit)) tripped = std::min(tripped, i);
    if (!ps_.held[i]) v[i] += h * inv_m * f[i];
    const double p0 = ps_.plastic[i], a0 = ps_.adhesion_max[i];
    const double dp = UpdatePlasticDeformation(
        soil_, p0, a0, PlasticDrive{ps_.max_repulsion[i], ps_.normal_sum[i], ps_.adhesion_reach[i], ps_.contacts[i]}, dt_);
    if (dp != p0) {
      ps_.plastic[i] = dp;
      ps_.adhesion_max[i] = MaxAdhesionForce(soil_, dp);
      ++changed;
    }
    if (ledger) {
      PlasticChange& r = plastic_rec_[i];
      r.x = x[i];
      r.p0 = p0;
      r.a0 = a0;
      r.p1 = ps_.plastic[i];
      r.a1 = ps_.adhesion_max[i];
    }
  }
  if (tripped < n) ReportOverlapTrip(ps_, tripped, soil_.diameter, settings_.max_overlap, step_, time_);
  sums_started_ = true;
  if (ledger && changed > 0) PlasticExchange();
}

void DemSystem::PlasticExchange() {
  // the energy the changed deformations (and adhesions) moved, at the positions they changed at:
  // every listed pair with a changed end, its normal energy after less before (per slot, on the
  // pair kernel's instance; the records the step's plastic update wrote), summed in slot order
  // (the same sum on any number of threads)
  const int n = ps_.slots();
  PlasticExchangeEnergies(law_, soil_.diameter, Threads(), ps_, lists_, plastic_rec_.data(), plastic_de_.data(),
                          settings_.pair_kernel);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += plastic_de_[i];
  ledger_.plastic += sum;
  ledger_.exchanged += sum;
}

// ---------------------------------------------------------------------------------------------
// energy and bookkeeping

EnergyReport DemSystem::Energy() const {
  EnergyReport e = MechanicalEnergy(EnergyTerms(), ps_, lists_);
  if (!finalized_) return e;
  e.wall_work = ledger_.wall_work;
  e.exchanged = ledger_.exchanged;
  e.dissipated = ledger_.wall_work + ledger_.exchanged - (e.Total() - ledger_.e0);
  return e;
}

DemContactSummary DemSystem::ContactSummary() const {
  DemContactSummary out;
  const double D = soil_.diameter;
  double normal = 0.0, adhesion = 0.0, repulsion = 0.0;
  long adhesive = 0;
  auto pair = [&](int i, int j) {
    const Vector3d r = ps_.x[i] - ps_.x[j];
    const double dist = r.norm(), d = D - dist - (ps_.plastic[i] + ps_.plastic[j]);
    if (!(d > 0.0) || dist <= 0.0) return;
    const double vn = (ps_.v[i] - ps_.v[j]).dot(r / dist);
    const SoilNormalForce fn = law_.Normal(d, -vn, std::min(ps_.adhesion_max[i], ps_.adhesion_max[j]));
    ++out.contacts;
    normal += fn.Total();
    adhesion += fn.adhesion;
    repulsion += fn.repulsion;
    adhesive += d < law_.d0;
  };
  for (int i = 0; i < ps_.slots(); ++i) {
    if (!ps_.live(i)) continue;
    for (int k = lists_.begin(i); k < lists_.end(i); ++k) pair(i, lists_.partners()[k]);
  }
  if (out.contacts > 0) {
    const double n = static_cast<double>(out.contacts);
    out.mean_normal = normal / n;
    out.mean_adhesion = adhesion / n;
    out.mean_repulsion = repulsion / n;
    out.adhesive_fraction = adhesive / n;
  }
  return out;
}

size_t DemSystem::MemoryBytes() const {
  return ps_.MemoryBytes() + lists_.MemoryBytes() + walls_.MemoryBytes() +
         plastic_rec_.capacity() * sizeof(PlasticChange) + plastic_de_.capacity() * sizeof(double);
}

Vector3d DemSystem::Momentum() const {
  Vector3d p = Vector3d::Zero();
  for (int i = 0; i < ps_.slots(); ++i)
    if (ps_.live(i)) p += mass_ * ps_.v[i];
  return p;
}

template <class Ar>
void DemSystem::Io(Ar& ar) {
  ar.Tag("dem");
  ar(gravity_, dt_, time_, step_, builds_, overflow_builds_, finalized_, rebuild_, ledger_, plastic_ledger_);
  ps_.Io(ar);
  lists_.Io(ar);
  walls_.Io(ar);
  if constexpr (Ar::kLoading) {
    const size_t n = ps_.x.size();
    if (lists_.list_begin().size() != n) ar.Fail("the neighbour lists do not match the particle slots");
    if (!walls_.Holds(static_cast<int>(n))) ar.Fail("the walls' contacts do not match the particle slots");
    sums_started_ = false;  // (scratch: the first step starts them)
  }
}
template void DemSystem::Io(StateWriter&);
template void DemSystem::Io(StateReader&);

}  // namespace dem_mobility::core
