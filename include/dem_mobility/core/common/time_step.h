// The explicit time-step guard's vocabulary, shared by the multibody core, the DEM and the
// co-simulation: the critical step of a damped oscillator and the limit a model reports.
#pragma once

#include <string>

namespace dem_mobility::core {

/// Critical explicit step of a damped oscillator: (2/omega)(sqrt(1+zeta^2) - zeta); infinite for
/// omega <= 0.
double CriticalStep(double omega, double zeta);

/// A model's time-step limit: the smallest critical step over its elements, and which element.
struct TimeStepLimit {
  double dt_crit = 0.0;
  std::string element;
  std::string detail;
  template <class Ar>
  void Io(Ar& ar) {
    ar(dt_crit, element, detail);
  }
};

}  // namespace dem_mobility::core
