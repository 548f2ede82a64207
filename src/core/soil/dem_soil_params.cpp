#include "dem_mobility/core/soil/dem_soil_params.h"

#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

SoilBinLevel ReadBinLevel(const YamlReader& y, const std::string& name) {
  SoilBinLevel l;
  l.name = name;
  l.particle_diameter = y.DoubleIn("particle_diameter", 0.005, 0.5);
  l.length = y.DoubleIn("length", 0.1, 1000.0);
  l.width = y.DoubleIn("width", 0.1, 100.0);
  l.soil_depth = y.DoubleIn("soil_depth", 0.05, 10.0);
  l.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  l.settle_time = y.DoubleIn("settle_time", 0.0, 100.0);
  l.hold_time = y.DoubleIn("hold_time", 0.0, 100.0);
  if (y.Has("speed_error")) l.speed_error = y.DoubleIn("speed_error", 0.0, 100.0);
  if (y.Has("speed_error_note")) l.speed_error_note = y.String("speed_error_note");
  y.Finish();
  if (l.soil_depth < 3.0 * l.particle_diameter)
    y.Fail("soil_depth", "must be at least three particle diameters (" + detail::Concat(3.0 * l.particle_diameter) + " m)");
  return l;
}

}  // namespace

DemSoilParams DemSoilParams::Read(const YamlReader& y) {
  DemSoilParams p;
  p.file = y.file();
  p.soil = SoilParams::Read(YamlReader::Load(y.ResolvePath(y.String("soil"))));
  p.level = ReadFidelityLevel<SoilBinLevel>(y, ReadBinLevel);  // every level checked, the named one used
  p.friction = y.DoubleIn("friction", 0.0, 2.0);
  // the soil: f directly, or from a requested cone index through the calibration table made at
  // this level's particle size (a table at this size also names the CI of an f given directly)
  p.strength = SoilStrength::Read(y, p.level.particle_diameter, p.friction, /*name_ci_of_f=*/true);
  p.soil.diameter = p.level.particle_diameter;
  p.soil.cohesion_factor = p.strength.cohesion_factor;
  p.soil.friction = p.friction;
  p.threads = ReadThreads(y);
  p.seed = static_cast<unsigned>(y.Int("seed", 1));
  p.time_step_guard = y.Bool("time_step_guard", true);
  if (y.Has("bin")) {
    const YamlReader b = y.Child("bin");
    p.origin = b.Vector3("origin", Vector3d::Zero());
    p.solid_fraction = b.DoubleIn("solid_fraction", 0.2, 0.74, 0.58);
    p.consolidation = b.DoubleIn("consolidation", 0.3, 1.0, 0.7);
    p.max_overlap = b.DoubleIn("max_overlap", 0.05, 0.9, 0.4);
    b.Finish();
  }
  const YamlReader lid = y.Child("lid");
  p.prep.lid_pressure = lid.Positive("pressure");
  p.prep.lid_speed = lid.DoubleIn("speed", 1e-4, 10.0);
  p.prep.release_time = lid.DoubleIn("release_time", 0.0, 100.0);
  p.prep.timeout = lid.DoubleIn("timeout", 0.1, 1000.0, 30.0);
  lid.Finish();
  p.prep.settle_time = p.level.settle_time;
  p.prep.hold_time = p.level.hold_time;
  if (y.Has("tire_contact")) {
    const YamlReader t = y.Child("tire_contact");
    p.tire_friction = t.DoubleIn("friction", 0.0, 5.0, 0.5);
    p.tire_adhesion = t.DoubleIn("adhesion_factor", 0.0, 10.0, 0.0);
    p.wall_margin = t.DoubleIn("margin", 0.0, 1.0, 0.0);
    t.Finish();
  }
  if (y.Has("track_strip_width")) {
    p.strip_width = y.DoubleIn("track_strip_width", 0.0, 100.0);
    if (p.strip_width > 0.0 && !y.Has("patch"))
      y.Fail("track_strip_width", "soil only under the wheel tracks is an option of the vehicle's moving patch (no patch: here)");
  }
  if (y.Has("patch")) {
    p.patch = SoilPatchParams::Read(y.Child("patch"));
    const double h = p.patch.leveling_ahead + p.patch.leveling_radius;
    if (h > 0.5 * p.level.length)
      y.Fail("patch.leveling.ahead", detail::Concat("the leveling cylinder (", h, " m ahead of the front wheels) must lie within half the bin's length (",
                                                    0.5 * p.level.length, " m)"));
  }
  return p;
}

std::vector<std::pair<double, double>> DemSoilParams::SoilBands() const {
  if (strip_width <= 0.0) return {{-0.5 * level.width, 0.5 * level.width}};
  const double h = 0.5 * strip_width;
  return {{-strip_offset - h, -strip_offset + h}, {strip_offset - h, strip_offset + h}};
}

double DemSoilParams::SoilWidth() const { return strip_width > 0.0 ? 2.0 * strip_width : level.width; }

int DemSoilParams::ParticleCount() const {
  const double d = level.particle_diameter;
  const double poured = level.soil_depth / consolidation;
  return static_cast<int>(std::lround(solid_fraction * level.length * SoilWidth() * poured / (M_PI / 6.0 * d * d * d)));
}

void DemSoilParams::Describe(ResultFile* r) const {
  r->Set("fidelity", level.name);
  if (!time_step_guard) r->Set("soil_time_step_guard", false);
  r->Set("particle_diameter", level.particle_diameter);
  r->Set("cohesion_factor", strength.cohesion_factor);
  r->Set("friction", friction);
  if (std::isfinite(strength.requested_cone_index_psi)) r->Set("requested_cone_index_psi", strength.requested_cone_index_psi);
  const double ci = strength.ConeIndex();
  if (std::isfinite(ci))
    r->Set("cone_index_psi", ci);
  else
    r->Set("cone_index_psi", std::string("unknown: f given directly and no calibration table names its CI") +
                                 (strength.no_table_reason.empty() ? std::string() : " (" + strength.no_table_reason + ")"));
  if (strength.calibration) strength.calibration->Describe(r);
}

SoilPatchParams SoilPatchParams::Read(const YamlReader& y) {
  SoilPatchParams p;
  p.enabled = true;
  p.travel = y.DoubleIn("travel", 1.0, 1e5, p.travel);
  p.sphere_margin = y.DoubleIn("sphere_margin", 0.0, 10.0, p.sphere_margin);
  p.template_length = y.DoubleIn("template_length", 0.2, 100.0, p.template_length);
  p.seam_clearance = y.DoubleIn("seam_clearance", 0.5, 1.0, p.seam_clearance);
  if (y.Has("leveling")) {
    const YamlReader l = y.Child("leveling");
    p.leveling_ahead = l.DoubleIn("ahead", 0.0, 50.0, p.leveling_ahead);
    p.leveling_radius = l.DoubleIn("radius", 0.01, 1.0, p.leveling_radius);
    p.plate_length = l.DoubleIn("plate_length", 0.01, 10.0, p.plate_length);
    p.leveling_clearance = l.DoubleIn("clearance", 0.0, 10.0, p.leveling_clearance);
    l.Finish();
  }
  if (y.Has("check_window")) {
    const std::vector<double> w = y.DoubleList("check_window");
    if (w.size() != 2 || !(w[0] >= 0.0 && w[1] > w[0] && w[1] <= 50.0))
      y.Fail("check_window", "expected [from, to] in m ahead of the front wheels' centres, 0 <= from < to <= 50");
    p.check_from = w[0];
    p.check_to = w[1];
  }
  p.check_period = y.DoubleIn("check_period", 1e-4, 10.0, p.check_period);
  y.Finish();
  if (p.check_to > p.leveling_ahead - p.plate_length)
    y.Fail("check_window", detail::Concat("ends at ", p.check_to, " m, under the leveling plate (from ",
                                          p.leveling_ahead - p.plate_length, " m ahead of the front wheels)"));
  return p;
}

}  // namespace dem_mobility::core
