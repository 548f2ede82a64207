#include "dem_mobility/core/scenes/uniaxial_compression.h"

#include <chrono>
#include <cmath>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/soil/soil_prep.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

CompressionParams CompressionParams::Read(const YamlReader& y) {
  CompressionParams p;
  p.file = y.file();
  p.soil = ReadSceneSoil(y, "uniaxial_compression");
  p.particle_diameter = y.DoubleIn("particle_diameter", 0.005, 0.5);
  p.soil.diameter = p.particle_diameter;
  if (y.Has("cohesion_factor")) p.soil.cohesion_factor = y.DoubleIn("cohesion_factor", 0.05, 12.0);
  if (y.Has("friction")) p.soil.friction = y.DoubleIn("friction", 0.0, 2.0);
  p.cylinder_diameter = y.DoubleIn("cylinder_diameter", 0.05, 10.0);
  if (p.cylinder_diameter < 5.0 * p.particle_diameter) y.Fail("cylinder_diameter", "must hold at least 5 particle diameters");
  p.soil_depth = y.DoubleIn("soil_depth", 0.02, 10.0);
  p.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 100.0);
  p.hold_time = y.DoubleIn("hold_time", 0.0, 100.0);
  p.piston_speed = y.DoubleIn("piston_speed", 1e-4, 10.0);
  p.loading = y.DoubleList("loading");
  p.unloading = y.DoubleList("unloading");
  if (p.loading.empty()) y.Fail("loading", "needs at least one pressure");
  for (size_t k = 0; k < p.loading.size(); ++k)
    if (!(p.loading[k] > 0.0) || (k > 0 && !(p.loading[k] > p.loading[k - 1])))
      y.Fail("loading", "pressures must be > 0 and increasing");
  for (size_t k = 0; k < p.unloading.size(); ++k)
    if (!(p.unloading[k] > 0.0) || !(p.unloading[k] < (k > 0 ? p.unloading[k - 1] : p.loading.back())))
      y.Fail("unloading", "pressures must be > 0, decreasing, and below the last loading pressure");
  p.solid_fraction = y.DoubleIn("solid_fraction", 0.2, 0.74, 0.58);
  p.threads = ReadThreads(y);
  p.seed = static_cast<unsigned>(y.Int("seed", 1));
  y.Finish();
  return p;
}

CompressionResult RunUniaxialCompression(const CompressionParams& p) {
  CompressionResult r;
  const auto wall0 = std::chrono::steady_clock::now();
  const double d = p.particle_diameter, R = 0.5 * p.cylinder_diameter, area = M_PI * R * R;
  DemSettings st;
  st.threads = p.threads;
  DemSystem s(p.soil, st);
  const int count = static_cast<int>(std::lround(p.solid_fraction * area * p.soil_depth / (M_PI / 6.0 * d * d * d)));
  const int pw = AddCylinderBed(&s, R, count, 24, p.seed).lid;  // the lid is the piston
  r.particles = s.num_alive();
  const double mass = r.particles * s.mass();
  try {
    s.Finalize(p.time_step);
    for (long n = std::lround(p.settle_time / p.time_step); n > 0; --n) s.Step();
    r.density_poured = mass / (area * LayerHeight(s));
    DemWall& w = s.mutable_wall(pw);
    w.position.z() = TopParticle(s) + 0.6 * d;
    // each pressure: the piston settles on it, holds it, and the density is read from the
    // piston's height (as in the apparatus)
    auto hold = [&](double pressure) {
      LidHold h(&s, pw, area, pressure, p.piston_speed, LidHold::Start::kWithin5Percent);
      const double limit = s.time() + 30.0;
      while (!h.holding() || h.held_time() < p.hold_time) {
        h.Step();
        if (s.time() > limit)
          throw SimulationError("uniaxial compression: the piston did not settle on " + detail::Concat(pressure) +
                                " Pa within 30 s");
      }
      CompressionPoint c;
      c.pressure = h.mean_pressure();
      c.density = mass / h.mean_volume();
      return c;
    };
    for (double pr : p.loading) r.loading.push_back(hold(pr));
    for (double pr : p.unloading) r.unloading.push_back(hold(pr));
    // the piston leaves; the soil's free surface after it
    w.velocity = Vector3d(0, 0, p.piston_speed);
    while (s.wall(pw).contacts > 0 || w.position.z() < TopParticle(s) + 0.6 * d) {
      w.position.z() += p.piston_speed * p.time_step;
      s.Step();
    }
    w.velocity.setZero();
    for (long n = std::lround(0.1 / p.time_step); n > 0; --n) s.Step();
    r.density_released = mass / (area * LayerHeight(s));
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  r.sim_time = s.time();
  r.steps = s.step_count();
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

ResultFile CompressionResultFile(const CompressionResult& r, const CompressionParams& p) {
  ResultFile f(p.file, "uniaxial_compression");
  f.SetStatus(r.error.empty() ? "ok" : "error", r.error);
  f.Set("particles", r.particles);
  f.Set("cohesion_factor", p.soil.cohesion_factor);
  f.Set("bulk_density_poured", r.density_poured);
  auto points = [&](const char* key, const std::vector<CompressionPoint>& v) {
    YAML::Node n(YAML::NodeType::Sequence);  // rows [pressure Pa, bulk density kg/m^3]
    for (const CompressionPoint& c : v) {
      YAML::Node row(YAML::NodeType::Sequence);
      row.push_back(c.pressure);
      row.push_back(c.density);
      row.SetStyle(YAML::EmitterStyle::Flow);
      n.push_back(row);
    }
    f.Set(key, n);
  };
  points("loading", r.loading);
  points("unloading", r.unloading);
  f.Set("bulk_density_released", r.density_released);
  f.Set("simulated_time", r.sim_time);
  f.Set("steps", r.steps);
  f.Set("wall_time", r.wall_time);
  return f;
}

}  // namespace dem_mobility::core
