#include "dem_mobility/core/dem/soil_law.h"

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

SoilParams SoilParams::Read(const YamlReader& y) {
  SoilParams p;
  p.file = y.file();
  p.diameter = y.DoubleIn("diameter", 1e-4, 1.0);
  p.density = y.DoubleIn("density", 1.0, 2e4);
  p.stiffness_stress = y.Positive("stiffness_stress");
  p.damping_area = y.NonNegative("damping_area");
  p.separation_factor = y.DoubleIn("separation_factor", 0.0, 1.0);
  p.adhesion_depth = y.DoubleIn("adhesion_depth", 0.0, 0.2);
  p.adhesion_peak = y.DoubleIn("adhesion_peak", 0.0, 0.2);
  if (p.adhesion_depth > 0.0 && !(p.adhesion_peak > 0.0 && p.adhesion_peak < p.adhesion_depth))
    y.Fail("adhesion_peak", "must lie strictly between 0 and adhesion_depth (" + detail::Concat(p.adhesion_depth) +
                                "), found " + detail::Concat(p.adhesion_peak));
  p.friction = y.DoubleIn("friction", 0.0, 5.0);
  p.tangential_stiffness_ratio = y.DoubleIn("tangential_stiffness_ratio", 0.0, 2.0);
  p.slip_velocity = y.Positive("slip_velocity");
  p.viscosity = y.NonNegative("viscosity");
  p.cohesion_factor = y.DoubleIn("cohesion_factor", 0.0, 100.0);
  p.relax_speed = y.NonNegative("relax_speed");
  p.plasticity = y.Bool("plasticity", true);
  p.cohesion = y.Bool("cohesion", true);
  p.plastic_strain_vs_stress = y.Table("plastic_strain_vs_stress");
  p.adhesion_stress_vs_plastic_strain = y.Table("adhesion_stress_vs_plastic_strain");
  for (double e : p.plastic_strain_vs_stress.y())
    if (!(e >= 0.0 && e < 0.5)) y.Fail("plastic_strain_vs_stress", "plastic strains must lie in [0, 0.5)");
  for (double s : p.adhesion_stress_vs_plastic_strain.y())
    if (!(s >= 0.0)) y.Fail("adhesion_stress_vs_plastic_strain", "adhesion stresses must be >= 0");
  y.Finish();
  return p;
}

double SoilParams::Mass() const { return density * M_PI * diameter * diameter * diameter / 6.0; }

double MaxAdhesionForce(const SoilParams& p, double delta_p) {
  if (!p.cohesion) return 0.0;
  return p.cohesion_factor * p.adhesion_stress_vs_plastic_strain(delta_p / p.diameter) * p.Area();
}

}  // namespace dem_mobility::core
