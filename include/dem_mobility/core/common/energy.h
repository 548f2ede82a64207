// Energy bookkeeping, the same report for the multibody system and the DEM particles.
#pragma once

#include <algorithm>
#include <cmath>

namespace dem_mobility::core {

struct EnergyReport {
  using StateBulk = void;  // (a checkpoint copies it as bytes: common/state_archive.h)
  double kinetic = 0.0;
  double gravitational = 0.0;  ///< -m g . x summed
  double elastic = 0.0;        ///< penalty springs, springs, contacts
  double Total() const { return kinetic + gravitational + elastic; }
  // the ledger since the start (models that keep one; zero otherwise)
  double wall_work = 0.0;      ///< work of moving walls on the system (trapezoidal in time)
  double exchanged = 0.0;      ///< energy of parts added less that of parts removed, and of gravity changes
  double dissipated = 0.0;     ///< wall_work + exchanged - (Total() - Total() at the start)
};

/// How far a stable run's dissipated energy may fall below zero, as a fraction of the energy through
/// its ledger (LedgerWatch::Scale()): the explicit integrator's energy error, far above round-off;
/// an unstable step leaves it within a few steps (docs/stability.md).
constexpr double kLedgerTolerance = 1e-3;

/// Follows a ledger along a run from its first sample: the energy dissipated since then, the least
/// value that reached (a stable run dissipates: it never falls below zero beyond the integrator's
/// error), the largest fall between two samples, and the energy that passed through the ledger
/// (the changes of wall_work and exchanged, summed in magnitude, plus the largest kinetic
/// energy): the scale a fall is judged against (stability matrix, docs/stability.md).
struct LedgerWatch {
  int samples = 0;
  double dissipated = 0.0;      ///< since the first sample [J]
  double least = 0.0, least_time = 0.0;
  double largest_fall = 0.0;    ///< the largest decrease of `dissipated` between two samples [J]
  double throughput = 0.0;      ///< [J]
  double kinetic_max = 0.0;

  void Sample(const EnergyReport& e, double t) {
    if (samples++ == 0) {
      base_ = e.dissipated;
    } else {
      throughput += std::abs(e.wall_work - last_work_) + std::abs(e.exchanged - last_exchanged_);
    }
    const double d = e.dissipated - base_;
    // (a NaN stays visible: the comparisons below would drop it)
    if (!std::isfinite(d)) nan_ = true;
    largest_fall = std::max(largest_fall, dissipated - d);
    dissipated = d;
    if (d < least) {
      least = d;
      least_time = t;
    }
    kinetic_max = std::max(kinetic_max, e.kinetic);
    last_work_ = e.wall_work;
    last_exchanged_ = e.exchanged;
  }
  /// The least scale falls are judged against [J] (a system's weight times a length of its own: a
  /// settling system moves energy between gravity and its springs before anything passes through)
  double floor = 0.0;
  /// The scale falls are judged against [J].
  double Scale() const { return std::max(floor, throughput + kinetic_max); }
  /// Whether the ledger fell below zero by more than `tolerance` of Scale(), or is not finite.
  bool Broken(double tolerance) const { return nan_ || least < -tolerance * Scale(); }
  bool finite() const { return !nan_; }
  /// Its state in a checkpoint (common/state_archive.h).
  template <class Ar>
  void Io(Ar& ar) {
    ar(samples, dissipated, least, least_time, largest_fall, throughput, kinetic_max, floor, base_, last_work_,
       last_exchanged_, nan_);
  }

 private:
  double base_ = 0.0, last_work_ = 0.0, last_exchanged_ = 0.0;
  bool nan_ = false;
};

}  // namespace dem_mobility::core
