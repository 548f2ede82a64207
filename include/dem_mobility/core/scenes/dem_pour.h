// The paper's soil preparation (section 4.2): particles poured into a box settle under gravity;
// a lid then consolidates them at a pressure (33.3 kPa) for a time (0.5 s) and is removed. The
// result is the bulk density and the layer height before and after the consolidation.
#pragma once

#include <memory>
#include <string>

#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {

class ResultFile;
class YamlReader;

struct DemPourParams {
  std::string file;
  SoilParams soil;
  double box_length = 0.0, box_width = 0.0;  ///< inner size of the box [m]
  int particles = 0;
  double time_step = 1.5e-5;
  int threads = 1;
  double settle_time = 0.5;      ///< [s] after the pour, before the lid
  double lid_pressure = 33.3e3;  ///< [Pa]
  double lid_speed = 0.05;       ///< [m/s] approach and retreat speed
  double hold_time = 0.5;        ///< [s] at the pressure
  double release_time = 0.2;     ///< [s] of settling after the lid is gone
  unsigned seed = 1;
  static DemPourParams Read(const YamlReader& y);
};

struct DemPourResult {
  int particles = 0;
  double height_poured = 0.0, density_poured = 0.0;        ///< after settling [m], [kg/m^3]
  double height_consolidated = 0.0, density_consolidated = 0.0;  ///< after the lid is removed
  double lid_pressure_reached = 0.0;   ///< mean over the hold [Pa]
  double mean_plastic_strain = 0.0;    ///< delta_p / d averaged over the particles
  double sim_time = 0.0, wall_time = 0.0, time_step = 0.0;
  long steps = 0;
  std::string error;
};

/// Runs the pour, settle, consolidate and release; numerical failures end it with `error` set and
/// the figures measured so far. With `keep`, the prepared bed is handed over (to run on).
DemPourResult RunDemPour(const DemPourParams& p, std::unique_ptr<DemSystem>* keep = nullptr);
/// The result file (the one schema: scene, kind, status, error, then the figures).
ResultFile DemPourResultFile(const DemPourResult& r, const DemPourParams& p);

}  // namespace dem_mobility::core
