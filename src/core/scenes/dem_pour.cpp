#include "dem_mobility/core/scenes/dem_pour.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/scenes/soil_prep.h"

namespace dem_mobility {

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

double LayerHeight(const DemSystem& s) {
  std::vector<double> z;
  z.reserve(s.size());
  s.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) { z.push_back(x.z()); });
  if (z.empty()) return 0.0;
  const size_t top = std::max<size_t>(1, z.size() / 20);
  std::partial_sort(z.begin(), z.begin() + top, z.end(), std::greater<double>());
  double sum = 0.0;
  for (size_t i = 0; i < top; ++i) sum += z[i];
  return sum / top + 0.5 * s.soil().diameter;
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
  try {
    s.Finalize(p.time_step);
    auto run_for = [&](double t) {
      const long n = std::lround(t / p.time_step);
      for (long i = 0; i < n; ++i) s.Step();
    };
    run_for(p.settle_time);
    r.height_poured = LayerHeight(s);
    r.density_poured = mass / (area * r.height_poured);
    // the lid settles on the target pressure (LidPress); the hold time counts from when the
    // particles first carry 95 % of the force
    const double target = p.lid_pressure * area;
    DemWall& lw = s.mutable_wall(lid_index);
    lw.position.z() = TopParticle(s) + 0.6 * D;  // just clear of the highest particle
    const LidPress press(target, p.lid_speed, p.time_step, area / (D * D) * p.soil.NormalStiffness());
    double held = -1.0, pressure_sum = 0.0;
    long hold_steps = 0;
    const double t_limit = s.time() + 60.0;
    while (held < p.hold_time) {
      const double fz = s.wall(lid_index).force.z();  // the particles push the lid up
      const double v = press.Velocity(fz);
      lw.velocity = Vector3d(0, 0, v);
      lw.position.z() += v * p.time_step;
      s.Step();
      if (held < 0.0 && fz >= 0.95 * target) held = 0.0;
      if (held >= 0.0) {
        held += p.time_step;
        pressure_sum += s.wall(lid_index).force.z() / area;
        ++hold_steps;
      }
      if (s.time() > t_limit) throw SimulationError("the lid did not reach its pressure within 60 s");
    }
    r.lid_pressure_reached = pressure_sum / std::max(1L, hold_steps);
    // the lid goes back up at lid_speed until it is one diameter clear of every particle, then away
    for (;;) {
      if (lw.position.z() > TopParticle(s) + 0.6 * D && s.wall(lid_index).contacts == 0) break;
      lw.velocity = Vector3d(0, 0, p.lid_speed);
      lw.position.z() += p.lid_speed * p.time_step;
      s.Step();
      if (s.time() > t_limit + 60.0) throw SimulationError("the lid did not come free of the particles within 60 s");
    }
    lw.velocity.setZero();
    lw.position.z() = H + a;
    run_for(p.release_time);
    r.height_consolidated = LayerHeight(s);
    r.density_consolidated = mass / (area * r.height_consolidated);
  } catch (const SimulationError& e) {
    r.error = e.what();
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

void WriteDemPourResult(const DemPourResult& r, const DemPourParams& p, const std::string& path) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "scene" << YAML::Value << p.file;
  e << YAML::Key << "particles" << YAML::Value << r.particles;
  e << YAML::Key << "layer_height_poured" << YAML::Value << r.height_poured;
  e << YAML::Key << "bulk_density_poured" << YAML::Value << r.density_poured;
  e << YAML::Key << "lid_pressure_reached" << YAML::Value << r.lid_pressure_reached;
  e << YAML::Key << "layer_height_consolidated" << YAML::Value << r.height_consolidated;
  e << YAML::Key << "bulk_density_consolidated" << YAML::Value << r.density_consolidated;
  e << YAML::Key << "mean_plastic_strain" << YAML::Value << r.mean_plastic_strain;
  e << YAML::Key << "time_step" << YAML::Value << r.time_step;
  e << YAML::Key << "steps" << YAML::Value << r.steps;
  e << YAML::Key << "simulated_time" << YAML::Value << r.sim_time;
  e << YAML::Key << "wall_time" << YAML::Value << r.wall_time;
  e << YAML::Key << "particle_steps_per_second" << YAML::Value
    << (r.wall_time > 0 ? r.particles * static_cast<double>(r.steps) / r.wall_time : 0.0);
  e << YAML::Key << "error" << YAML::Value << r.error;
  e << YAML::EndMap;
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the result file");
  out << e.c_str() << "\n";
}

}  // namespace dem_mobility
