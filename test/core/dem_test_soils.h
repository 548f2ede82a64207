// Soils the DEM tests share: the nominal clay, and a plain linear spring-dashpot made from it.
#pragma once

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/soil_law.h"

namespace dem_mobility::core {

inline SoilParams Nominal() { return SoilParams::Read(YamlReader::Load(DM_CONFIG_DIR "/soils/nominal_clay.yaml")); }

// no adhesion, no plasticity, no friction; damping the same on approach and separation
inline SoilParams Elastic(double damping_area) {
  SoilParams p = Nominal();
  p.cohesion = false;
  p.plasticity = false;
  p.adhesion_depth = p.adhesion_peak = 0.0;
  p.friction = 0.0;
  p.damping_area = damping_area;
  p.separation_factor = 1.0;
  return p;
}

}  // namespace dem_mobility::core
