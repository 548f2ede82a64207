#include "dem_mobility/core/scenes/soil_rig.h"

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

void RunSoilRig(SoilRig& rig, const std::function<void(const SoilRig&)>& progress, long every) {
  try {
    while (!rig.done()) {
      rig.Step();
      if (progress && rig.dem().step_count() % every == 0) progress(rig);
    }
  } catch (const SimulationError& e) {
    rig.Fail(e.what());
  }
}

}  // namespace dem_mobility::core
