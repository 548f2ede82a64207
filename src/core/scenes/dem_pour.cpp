#include "dem_mobility/core/scenes/dem_pour.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/soil/soil_prep.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

DemPourParams DemPourParams::Read(const YamlReader& y) {
  DemPourParams p;
  p.file = y.file();
  p.soil = ReadSceneSoil(y, "dem_pour");
  const YamlReader box = y.Child("box");
  p.box_length = box.Positive("length");
  p.box_width = box.Positive("width");
  box.Finish();
  p.particles = y.Int("particles");
  if (p.particles < 1 || p.particles > 5000000) y.Fail("particles", "must lie in [1, 5e6]");
  p.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  p.threads = ReadThreads(y);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 100.0);
  const YamlReader lid = y.Child("lid");
  p.lid_pressure = lid.Positive("pressure");
  p.lid_speed = lid.DoubleIn("speed", 1e-4, 10.0);
  p.hold_time = lid.DoubleIn("hold_time", 0.0, 100.0);
  p.release_time = lid.DoubleIn("release_time", 0.0, 100.0);
  lid.Finish();
  p.seed = static_cast<unsigned>(y.Int("seed", 1));
  y.Finish();
  if (p.box_length < 3 * p.soil.diameter || p.box_width < 3 * p.soil.diameter)
    y.Fail("box", "must be at least 3 particle diameters wide");
  return p;
}

DemPourResult RunDemPour(const DemPourParams& p, std::unique_ptr<DemSystem>* keep) {
  DemPourResult r;
  const auto wall0 = std::chrono::steady_clock::now();
  const double D = p.soil.diameter, L = p.box_length, W = p.box_width;
  DemSettings st;
  st.threads = p.threads;
  auto system = std::make_unique<DemSystem>(p.soil, st);
  DemSystem& s = *system;
  // a loose jittered lattice (spacing 1.2 d) over the box, as many layers as it takes: it falls
  // and settles as a poured bed
  const double a = 1.2 * D;
  const std::vector<Vector3d> lattice = PourLattice(p.particles, D, 1.2, {0.0, 0.0}, {L, W},
                                                    [](double, double) { return true; }, p.seed);
  double z_max = 0.0;
  for (const Vector3d& x : lattice) z_max = std::max(z_max, x.z());
  const double H = z_max + 2 * a;
  for (DemWall& w : MakeOpenBoxWalls(L, W, H)) s.AddWall(std::move(w));
  DemWall lid = MakeQuadWall("lid", {0, 0, 0}, {0, W, 0}, {L, 0, 0});  // normal down
  lid.position = Vector3d(0, 0, H + a);
  const int lid_index = s.AddWall(lid);
  for (const Vector3d& x : lattice) s.AddParticle(x);
  r.particles = s.size();
  r.time_step = p.time_step;
  const double mass = s.size() * s.mass(), area = L * W;
  SoilPreparationParams sp;
  sp.settle_time = p.settle_time;
  sp.lid_pressure = p.lid_pressure;
  sp.lid_speed = p.lid_speed;
  sp.hold_time = p.hold_time;
  sp.release_time = p.release_time;
  sp.timeout = 60.0;
  std::unique_ptr<SoilPreparation> prep;
  try {
    s.Finalize(p.time_step);
    prep = std::make_unique<SoilPreparation>(&s, lid_index, area, H + a, sp, "dem_pour");
    while (!prep->done()) prep->Step();
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  if (prep) {
    r.height_poured = prep->height_poured();
    if (r.height_poured > 0.0) r.density_poured = mass / (area * r.height_poured);
    r.lid_pressure_reached = prep->lid_pressure_reached();
    r.height_consolidated = prep->height_consolidated();
    if (r.height_consolidated > 0.0) r.density_consolidated = mass / (area * r.height_consolidated);
  }
  double strain = 0.0;
  for (double dp : s.plastic_deformations()) strain += dp / D;
  r.mean_plastic_strain = strain / std::max(1, s.size());
  r.steps = s.step_count();
  r.sim_time = s.time();
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (keep) *keep = std::move(system);
  return r;
}

ResultFile DemPourResultFile(const DemPourResult& r, const DemPourParams& p) {
  ResultFile f(p.file, "dem_pour");
  f.SetStatus(r.error.empty() ? "ok" : "error", r.error);
  f.Set("particles", r.particles);
  f.Set("layer_height_poured", r.height_poured);
  f.Set("bulk_density_poured", r.density_poured);
  f.Set("lid_pressure_reached", r.lid_pressure_reached);
  f.Set("layer_height_consolidated", r.height_consolidated);
  f.Set("bulk_density_consolidated", r.density_consolidated);
  f.Set("mean_plastic_strain", r.mean_plastic_strain);
  f.Set("time_step", r.time_step);
  f.Set("steps", r.steps);
  f.Set("simulated_time", r.sim_time);
  f.Set("wall_time", r.wall_time);
  f.Set("particle_steps_per_second", r.wall_time > 0 ? r.particles * static_cast<double>(r.steps) / r.wall_time : 0.0);
  return f;
}

}  // namespace dem_mobility::core
