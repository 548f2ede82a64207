#include "dem_mobility/core/common/time_step.h"

#include <cmath>
#include <limits>

namespace dem_mobility::core {

double CriticalStep(double omega, double zeta) {
  if (!(omega > 0.0)) return std::numeric_limits<double>::infinity();
  return (2.0 / omega) * (std::sqrt(1.0 + zeta * zeta) - zeta);
}

}  // namespace dem_mobility::core
