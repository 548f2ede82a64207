#include "dem_mobility/core/scenes/soil_prep.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"

namespace dem_mobility {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Vector3d> PourLattice(int count, double d, double spacing, const Vector2d& lo, const Vector2d& hi,
                                  const std::function<bool(double, double)>& inside, unsigned seed) {
  const double a = spacing * d;
  std::vector<Vector2d> layer;
  for (double y = lo.y() + 0.6 * d; y <= hi.y() - 0.6 * d; y += a)
    for (double x = lo.x() + 0.6 * d; x <= hi.x() - 0.6 * d; x += a)
      if (inside(x, y)) layer.emplace_back(x, y);
  DM_THROW_UNLESS(!layer.empty(), "the pour region holds no particle of diameter ", d);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.08 * d, 0.08 * d);
  std::vector<Vector3d> out;
  out.reserve(count);
  for (int n = 0; n < count; ++n) {
    const Vector2d& p = layer[n % layer.size()];
    const int k = n / static_cast<int>(layer.size());
    out.emplace_back(p.x() + jitter(rng), p.y() + jitter(rng), 0.6 * d + k * a + jitter(rng));
  }
  return out;
}

LidPress::LidPress(double target_force, double max_speed, double dt, double k_layer)
    : target_(target_force), v_max_(std::min(max_speed, 0.5 * target_force / (dt * k_layer))) {
  DM_THROW_UNLESS(target_force > 0.0 && max_speed > 0.0 && dt > 0.0 && k_layer > 0.0,
                  "lid: target force, speed, time step and layer stiffness must be > 0");
}

double LidPress::Velocity(double fz) const {
  return std::clamp(-v_max_ * (target_ - fz) / target_, -v_max_, v_max_);
}

CylinderBed AddCylinderBed(DemSystem* s, double R, int count, int segments, unsigned seed) {
  const double d = s->soil().diameter;
  const std::vector<Vector3d> lattice = PourLattice(
      count, d, 1.1, {-R, -R}, {R, R}, [&](double x, double y) { return x * x + y * y <= (R - 0.6 * d) * (R - 0.6 * d); },
      seed);
  double top = 0.0;
  for (const Vector3d& x : lattice) top = std::max(top, x.z());
  CylinderBed bed;
  bed.wall_height = top + 2.0 * d;
  bed.floor = s->AddWall(MakeDiskWall("floor", 1.1 * R, segments));
  for (DemWall& w : MakeCylinderSideWalls("container", R, bed.wall_height, segments)) s->AddWall(std::move(w));
  DemWall lid = MakeDiskWall("lid", R, segments);
  lid.position = Vector3d(0, 0, top + d);
  bed.lid = s->AddWall(std::move(lid));
  for (const Vector3d& x : lattice) s->AddParticle(x);
  return bed;
}

int ReadThreads(const YamlReader& y) {
  const int threads = y.Int("threads", 1);
  if (threads < 1 || threads > 256) y.Fail("threads", "must lie in [1, 256]");
  return threads;
}

SoilParams ReadSceneSoil(const YamlReader& y, const std::string& kind) {
  const std::string scene = y.String("scene");
  if (scene != kind) y.Fail("scene", "expected '" + kind + "', found '" + scene + "'");
  return SoilParams::Read(YamlReader::Load(y.ResolvePath(y.String("soil"))));
}

double TopParticle(const DemSystem& s) {
  double top = 0.0;
  s.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) { top = std::max(top, x.z()); });
  return top;
}

}  // namespace dem_mobility
