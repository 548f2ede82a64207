// What the soil patch's tests share (soil_patch_test.cpp, vehicle_on_soil_test.cpp: one test
// program): the tiny level's soils, prepared once per soil for the whole program (a copy each),
// the wheels' states and drive, and the soil scene. Inline, so that one preparation serves both
// files.
#pragma once

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/cosim_loop.h"
#include "dem_mobility/core/mobility/mobility_run.h"
#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core::soil_test {

using Eigen::Vector3d;

inline const std::string kTerrain = DM_CONFIG_DIR "/terrains/soil_patch.yaml";
inline const std::string kScene = DM_CONFIG_DIR "/scenes/soil_slope.yaml";

inline VehicleSpec Hmmwv() { return VehicleSpec::Load(DM_CONFIG_DIR "/vehicles/hmmwv/vehicle.yaml"); }

/// The tiny level's soil: of cone index `ci` (through the level's table), or (ci <= 0) of
/// cohesion factor f = -ci given directly (the patch's own tests need no particular strength);
/// `length`: of the box (0: the level's 9.3 m; the vehicle's tests take a shorter box, an option
/// the scene allows, to keep the suite short).
inline DemSoilParams TinySoil(double ci, double length = 0.0) {
  std::ifstream in(kTerrain);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = std::regex_replace(ss.str(), std::regex("\nfidelity:[^\n]*"), "\nfidelity: tiny");
  text = std::regex_replace(text, std::regex("\nthreads:[^\n]*"), "\nthreads: 1");
  if (ci <= 0)
    text = std::regex_replace(text, std::regex("\ncone_index:[^\n]*"), "\ncohesion_factor: " + std::to_string(-ci));
  else
    text = std::regex_replace(text, std::regex("\ncone_index:[^\n]*"), "\ncone_index: " + std::to_string(ci));
  if (length > 0.0) {
    // a short box lays its soil nearer the front wheels: the checks look nearer too
    // (MakeDemSoilTerrain refuses a box whose laid soil does not reach the window)
    const size_t cw = text.find("\n  check_window: [0.6, 1.4]");
    if (cw == std::string::npos) throw std::runtime_error("soil_patch.yaml: patch.check_window [0.6, 1.4] not found");
    text.replace(cw, std::string("\n  check_window: [0.6, 1.4]").size(), "\n  check_window: [0.3, 0.7]");
    // levels.tiny.length: the first `length:` after `  tiny:`
    const size_t tiny = text.find("\n  tiny:\n");
    const size_t at = tiny == std::string::npos ? tiny : text.find("    length: ", tiny);
    if (at == std::string::npos) throw std::runtime_error("soil_patch.yaml: levels.tiny.length not found");
    const size_t value = at + std::string("    length: ").size();
    text.replace(value, text.find('\n', value) - value, std::to_string(length));
  }
  const YamlReader y = YamlReader::FromString(text, kTerrain);
  DemSoilParams p = DemSoilParams::Read(y);
  y.String("model");
  y.Finish();
  return p;
}

/// Soils prepared by LoadTerrainModel are kept in, and read back from, the folder the test command
/// names (DM_SOIL_CACHE, scripts/test.sh): one preparation per soil for the whole suite.
inline PreparationHooks SuiteSoilCache() {
  PreparationHooks h;
  const char* dir = std::getenv("DM_SOIL_CACHE");
  if (dir) h.prepared_soil_cache = dir;
  return h;
}

/// One prepared patch per soil and box length for the whole binary; each test takes a copy.
inline std::unique_ptr<DemSoilTerrain> PreparedPatch(double ci, double length = 0.0) {
  static std::map<std::pair<double, double>, std::unique_ptr<DemSoilTerrain>> prepared;
  auto& t = prepared[{ci, length}];
  if (!t) t = std::make_unique<DemSoilTerrain>(TinySoil(ci, length), Hmmwv().tire, kWheels);
  return std::make_unique<DemSoilTerrain>(*t);
}

/// The mean height of the highest particle centre of each d x d column of the band
/// |y - y0| < half_width, over the columns holding particles (many small columns: the mean of their
/// tops scatters far less than one column's top does).
inline double TrackTop(const DemSystem& s, double y0, double half_width, double d) {
  std::map<std::pair<long, long>, double> top;
  s.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
    if (std::abs(x.y() - y0) >= half_width) return;
    const std::pair<long, long> c{std::lround(std::floor(x.x() / d)), std::lround(std::floor(x.y() / d))};
    auto it = top.find(c);
    if (it == top.end()) top[c] = x.z();
    else it->second = std::max(it->second, x.z());
  });
  double sum = 0.0;
  for (const auto& [c, z] : top) sum += z;
  return top.empty() ? std::numeric_limits<double>::quiet_NaN() : sum / static_cast<double>(top.size());
}

/// The vehicle's tests: a 6 m box (the vehicle fits with 1.3 m to spare at each end).
inline constexpr double kShortBox = 6.0;

/// The vehicle's driving tests take the soil only under the wheel tracks (track_strip_width 0.9 m,
/// an option the scene allows; half the particles of the whole width) in the 6 m box, loaded as a
/// scene loads its terrain: of cone index `ci`, one preparation per soil for the binary, a copy each.
inline std::unique_ptr<DemSoilTerrain> PreparedStrips(double ci) {
  static std::map<double, std::unique_ptr<DemSoilTerrain>> prepared;
  auto& t = prepared[ci];
  if (!t) {
    std::unique_ptr<TerrainModel> m = LoadTerrainModel(
        kTerrain, TerrainVehicleOf(Hmmwv()),
        {"fidelity=tiny", "threads=1", "cone_index=" + std::to_string(ci), "track_strip_width=0.9",
         "levels.tiny.length=" + std::to_string(kShortBox), "patch.check_window=[0.3, 0.7]"},
        SuiteSoilCache());
    t.reset(dynamic_cast<DemSoilTerrain*>(m.release()));
    if (!t) throw std::runtime_error("soil_patch.yaml: not a dem_soil terrain");
  }
  return std::make_unique<DemSoilTerrain>(*t);
}

/// Four wheel states of a vehicle whose wheel centroid is at x, at height z, moving at v along x
/// with the wheels rolling.
inline std::vector<WheelState> Wheels(double x, double z, double v, double r) {
  std::vector<WheelState> w(kWheels);
  const double xs[kWheels] = {1.65, 1.65, -1.65, -1.65}, ys[kWheels] = {0.9, -0.9, 0.9, -0.9};
  for (int i = 0; i < kWheels; ++i) {
    w[i].position = Vector3d(x + xs[i], ys[i], z);
    w[i].velocity = Vector3d(v, 0, 0);
    w[i].angular_velocity = Vector3d(0, v / r, 0);
  }
  return w;
}

/// Moves the wheels along x at v for `steps` soil steps (one exchange per step), from centroid x0,
/// their height from z to z1 (default z) over the steps.
inline void Drive(DemSoilTerrain* t, double x0, double z, double v, long steps, const std::function<void(long)>& each = {},
           double z1 = std::numeric_limits<double>::quiet_NaN()) {
  const double h = t->description().time_step, r = t->bin().tire().radius;
  if (std::isnan(z1)) z1 = z;
  std::vector<WheelWrench> w;
  for (long k = 0; k < steps; ++k) {
    t->Synchronize(k, k * h, Wheels(x0 + v * k * h, z + (z1 - z) * k / steps, v, r));
    t->GetWrenches(&w);
    t->Advance(h);
    if (each) each(k);
  }
}

/// Live particles whose positions differ, bit for bit, between two soils (of the same IDs).
inline long ParticlesThatDiffer(const DemSystem& a, const DemSystem& b) {
  const auto pa = a.positions(), pb = b.positions();
  if (pa.size() != pb.size()) return std::max(1L, std::labs(static_cast<long>(pa.size()) - static_cast<long>(pb.size())));
  long differ = 0;
  for (size_t i = 0; i < pa.size(); ++i)
    if (a.alive(static_cast<int>(i)) && (pa[i].array() != pb[i].array()).any()) ++differ;
  return differ;
}

inline MobilityRunParams SoilScene(double grade, const std::vector<std::string>& more = {}) {
  std::vector<std::string> o = {"grade_deg=" + std::to_string(grade)};
  o.insert(o.end(), more.begin(), more.end());
  return MobilityRunParams::Read(YamlReader::LoadWithOverrides(kScene, o));
}

}  // namespace dem_mobility::core::soil_test
