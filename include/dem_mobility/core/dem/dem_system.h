// The explicit DEM solver for the cohesive soil (paper section 2.3): point particles (3
// translational DOF) with a contact diameter, the soil law of soil_law.h between every pair,
// velocity Verlet (the explicit member of the multibody core's trapezoidal family), a Cartesian
// cell grid with a Verlet skin, and OpenMP. DemSystem is the facade over its parts:
//   particle_store.h   the particle slots, their stable IDs and the free slots
//   neighbour_list.h   the cell grid, the slabs and the half lists with their contact histories
//   pair_sweep.h       the pair forces, slab by slab (the same sums for any thread count)
//   wall_contacts.h    the walls, their candidate triangles, histories and wrenches
//   dem_energy.h       the energies and the ledger
//   dem_watchdogs.h    the critical time step and the per-step watchdogs
//
// The particle lists are rebuilt when a particle has moved more than half the skin since the
// build; the wall candidates also on their own, when a wall and the particles have together moved
// more than the walls' margin (wall_contacts.h). Particles can be added and removed between steps
// without a build: a new particle's pairs go into lists with a little spare room, and a removed
// particle's slot is reused by the next one added. The IDs of the other particles never change.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/time_step.h"
#include "dem_mobility/core/dem/dem_energy.h"
#include "dem_mobility/core/dem/neighbour_list.h"
#include "dem_mobility/core/dem/pair_sweep.h"
#include "dem_mobility/core/dem/particle_store.h"
#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/dem/wall_contacts.h"

namespace dem_mobility::core {

/// The pair contacts of the last force evaluation, summarised (what a benchmark prints so that a
/// reader sees what work its bed does): normal forces are signed, > 0 repulsive.
struct DemContactSummary {
  long contacts = 0;              ///< pairs with a positive effective penetration
  double mean_normal = 0.0;       ///< mean normal force (adhesion + repulsion + damping) [N]
  double mean_adhesion = 0.0;     ///< mean adhesive part (<= 0) [N]
  double mean_repulsion = 0.0;    ///< mean repulsive part [N]
  double adhesive_fraction = 0.0; ///< of the contacts, those inside the adhesion range (d < d0)
};

struct DemSettings {
  double skin = 0.1;            ///< Verlet skin as a fraction of the diameter
  int threads = 1;              ///< OpenMP threads
  double max_overlap = 0.25;    ///< watchdog: largest overlap / diameter before the run stops (the
                                ///< soil sits at d0 = 5 % and compacts plastically by up to ~8 % more)
  int max_coordination = 12;    ///< contacts per particle assumed by the time-step guard
  /// the guard: Finalize refuses a step above the critical one (false only for stability studies,
  /// which run past it to see what the guard prevents)
  bool check_time_step = true;
  int list_slack = 2;           ///< spare neighbour slots per particle for particles added later
  bool wall_bins = true;        ///< bin large walls' triangles (false: scan them all; same results)
  /// the pair kernel (pair_sweep.h): every choice gives the same results, bit for bit
  PairKernel pair_kernel = PairKernel::kAuto;
  /// below this many particle slots every pass runs on one thread: a parallel region's start and
  /// barriers cost more than such a pass (0: always on `threads`; the results are the same either way)
  int serial_below = 512;
};

class DemSystem {
 public:
  DemSystem(const SoilParams& soil, const DemSettings& settings);

  /// Adds a particle (before or between steps); returns its ID (0, 1, 2, ... in the order added;
  /// an ID is never reused). Between steps the neighbour lists are extended in place (no full
  /// rebuild, unless a neighbour's list has no spare room left).
  int AddParticle(const Eigen::Vector3d& x, const Eigen::Vector3d& v = Eigen::Vector3d::Zero());
  /// Removes a particle (between steps): its contacts vanish; its storage is reused.
  void RemoveParticle(int id);
  bool alive(int id) const { return ps_.alive(id); }
  int num_alive() const { return ps_.num_alive(); }
  /// Gravity in any direction (a grade is a rotated gravity vector). Changing it during a run
  /// enters the energy ledger as exchanged energy.
  void set_gravity(const Eigen::Vector3d& g);
  const Eigen::Vector3d& gravity() const { return gravity_; }
  /// Adds a wall (before Finalize); returns its index. A moving wall gets its pose and velocity
  /// set through mutable_wall() before each Step (prescribed motion, or a multibody body's state).
  int AddWall(DemWall wall);
  DemWall& mutable_wall(int w) { return walls_.wall(w); }
  const DemWall& wall(int w) const { return walls_.wall(w); }
  int num_walls() const { return walls_.size(); }

  TimeStepLimit CriticalTimeStep() const;
  /// Refuses (ConfigError naming the limit) a step above the critical one; computes the forces.
  void Finalize(double dt);
  /// One step. Throws SimulationError naming the step, the particle (ID) and the quantity when a
  /// watchdog trips (a non-finite state or force, an overlap beyond max_overlap, a particle moving
  /// more than half the skin in one step); the state at the failure stays readable (for saving).
  void Step();

  /// IDs handed out so far (removed particles included).
  int size() const { return ps_.size(); }
  long step_count() const { return step_; }
  double time() const { return time_; }
  double dt() const { return dt_; }
  // one particle by ID (a removed one: its last state until its storage is reused, then NaN)
  Eigen::Vector3d position(int id) const { return ps_.Get(ps_.x, id); }
  Eigen::Vector3d velocity(int id) const { return ps_.Get(ps_.v, id); }
  Eigen::Vector3d force(int id) const { return ps_.Get(ps_.f, id); }
  double plastic_deformation(int id) const { return ps_.Get(ps_.plastic, id); }
  Eigen::Vector3d& mutable_velocity(int id) { return ps_.v[ps_.LiveSlot(id)]; }
  Eigen::Vector3d& mutable_position(int id) { return ps_.x[ps_.LiveSlot(id)]; }
  /// Sets a live particle's plastic deformation [m] and with it its maximum adhesion (the
  /// consolidation-dependent adhesion of the soil law): a particle re-emitted with the state of the
  /// consolidated soil it replaces.
  void set_plastic_deformation(int id, double dp);
  /// Holds a live particle in place (true: its velocity is zeroed and it is not integrated until
  /// released; its contacts act on its neighbours as a fixed wall's would), or releases it. The
  /// moving soil patch holds the soil it has just laid down until the next layer is in front of it
  /// (as the bin's front wall held the bed). mutable_velocity() and mutable_position() still reach a
  /// held particle: a velocity given to it is not integrated, but enters its contacts' damping.
  void set_held(int id, bool held);
  bool held(int id) const { return ps_.held[ps_.LiveSlot(id)] != 0; }
  /// Calls f(id, position, velocity) for every live particle, in storage order (cheap: no copies).
  template <class F>
  void ForEachParticle(F&& f) const {
    for (int s = 0; s < ps_.slots(); ++s)
      if (ps_.live(s)) f(ps_.id_of_slot[s], ps_.x[s], ps_.v[s]);
  }
  /// OpenMP threads from the next step on (the results do not depend on it).
  void set_threads(int threads);
  /// The pair kernel from the next step on (kAuto resolved; a vector instance the CPU lacks is
  /// refused); the results do not depend on it.
  void set_pair_kernel(PairKernel kernel);
  PairKernel pair_kernel() const { return settings_.pair_kernel; }
  // all particles, indexed by ID (copies: the storage is kept sorted by cell, not by ID)
  std::vector<Eigen::Vector3d> positions() const;
  std::vector<Eigen::Vector3d> velocities() const;
  std::vector<double> plastic_deformations() const;
  const SoilParams& soil() const { return soil_; }
  /// Sets V_relax (eq. 16) from the next step on: how a bed at rest answers its plastic
  /// deformation being let relax (soil_rest_test), a study of V_relax.
  void set_relax_speed(double v) { soil_.relax_speed = v; }
  double mass() const { return mass_; }
  long neighbour_builds() const { return builds_; }
  /// Builds of the wall candidates (with every neighbour build, and on their own when walls move).
  long wall_builds() const { return walls_.builds(); }
  /// Wall candidate triangles over all particles at the last wall build.
  long wall_candidates() const { return walls_.candidates(); }
  const WallContacts& wall_contacts() const { return walls_; }
  /// The particles' per-slot arrays (read only; the benchmarks copy them).
  const ParticleStore& particles() const { return ps_; }
  /// Of those, the builds forced by an added particle whose neighbour's list had no room left.
  long overflow_builds() const { return overflow_builds_; }
  int contacts() const { return lists_.contacts(); }  ///< pairs in contact at the last force evaluation
  /// The pair contacts at the present state (the normal law on every listed pair; cheap enough for a
  /// report, not for every step).
  DemContactSummary ContactSummary() const;
  /// The energies now and the ledger since Finalize() (see EnergyReport: the ledger is kept).
  EnergyReport Energy() const;
  /// Keeps the contact law's plastic exchange in the ledger (DemLedger::plastic, in `exchanged`):
  /// then `dissipated` is what the dampers and the friction took, never negative in a stable run.
  /// Off by default (a pass over the pairs after every step in which a plastic deformation changed).
  void set_plastic_ledger(bool on) { plastic_ledger_ = on; }
  bool plastic_ledger() const { return plastic_ledger_; }
  /// The law's plastic exchange since set_plastic_ledger(true) [J].
  double plastic_exchange() const { return ledger_.plastic; }
  /// Bytes held for the particles, neighbour lists, contact histories and walls.
  size_t MemoryBytes() const;
  Eigen::Vector3d Momentum() const;
  /// Its state in a checkpoint (common/state_archive.h): the particles, lists, walls, clock and
  /// ledger. A system read back steps on exactly as the one written would have (its walls must
  /// be those of the same scene; the threads and the pair kernel stay this system's own).
  template <class Ar>
  void Io(Ar& ar);

 private:
  void Rebuild();
  /// The forces, maxima and overlaps (f, the plastic drive's sums, overlap) at the present state.
  void ComputeForces();
  /// Sums the pair and wall forces into the slots' sums (ps_.sums); `packed`: the step's drift
  /// packed every slot already (else they are packed here).
  void SumForces(bool packed);
  /// Adds the step's plastic changes' energy to the ledger (set_plastic_ledger).
  void PlasticExchange();
  /// The threads a pass runs on (settings_.serial_below).
  int Threads() const { return ps_.slots() < settings_.serial_below ? 1 : settings_.threads; }
  DemEnergyTerms EnergyTerms() const { return DemEnergyTerms{&law_, soil_.diameter, mass_, gravity_}; }

  SoilParams soil_;
  DemSettings settings_;
  SoilContactLaw law_;
  double mass_ = 0.0, cutoff_ = 0.0;
  Eigen::Vector3d gravity_{0, 0, -9.81};
  double dt_ = 0.0, time_ = 0.0;
  long step_ = 0, builds_ = 0, overflow_builds_ = 0;
  bool finalized_ = false, rebuild_ = true;
  /// ps_.sums hold every slot's start (its weight, or zero when free) for the next force
  /// evaluation: the last step's final pass started them and nothing has moved a slot or changed
  /// gravity since (scratch, not in a checkpoint)
  bool sums_started_ = false;
  ParticleStore ps_;
  NeighbourList lists_;
  WallContacts walls_;
  DemLedger ledger_;
  bool plastic_ledger_ = false;
  // the plastic pass's scratch, written and read within a step (not state: not in a checkpoint),
  // grown with the slots: each slot's record (pair_sweep.h's PlasticChange: what the pass reads of
  // it, packed into one cache line by the step's plastic update) and the energy change of its half
  // list's pairs
  std::vector<PlasticChange, Eigen::aligned_allocator<PlasticChange>> plastic_rec_;
  std::vector<double> plastic_de_;
};

}  // namespace dem_mobility::core
