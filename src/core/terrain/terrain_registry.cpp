// The registry of terrain kinds: one row per `model:` (the next kinds are added here).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "dem_mobility/core/common/registry.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/road_terrain.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

const std::vector<TerrainKind>& TerrainKinds() {
  static const std::vector<TerrainKind> kinds = {
      {"rigid_road", "a rigid polygonal road (tire vertices against its triangles, asperity friction)",
       [](const YamlReader& y, const TerrainVehicle& v, const PreparationHooks&) { return MakeRoadTerrain(y, v); },
       &DescribeRoadTerrain, &CheckRoadTerrain, /*restore: built by make, then its LoadState*/ nullptr},
      {"dem_soil", "a DEM soil bin (cohesive particles, prepared under a lid) the tires sink into",
       [](const YamlReader& y, const TerrainVehicle& v, const PreparationHooks& hooks) {
         return MakeDemSoilTerrain(y, v, hooks);
       },
       &DescribeDemSoilTerrain, &CheckDemSoilTerrain, &RestoreDemSoilTerrain},
  };
  return kinds;
}

std::string PreparationProgress::Line() const {
  char b[160];
  std::snprintf(b, sizeof b, "%s: %.3f s simulated in %.0f s, %d particles", phase.c_str(), simulated, wall, particles);
  return detail.empty() ? std::string(b) : std::string(b) + "; " + detail;
}

TerrainVehicle TerrainVehicleOf(const VehicleSpec& spec) {
  TerrainVehicle v;
  v.tire = spec.tire;
  v.wheels = kWheels;
  v.track = 2.0 * std::max(std::abs(spec.suspension_front.hardpoints.spindle.y()),
                           std::abs(spec.suspension_rear.hardpoints.spindle.y()));
  v.wheelbase = spec.wheelbase;
  return v;
}

namespace {
const TerrainKind& FindTerrainKind(const YamlReader& y) {
  return FindKind(y, "model", TerrainKinds(), [](const TerrainKind& k) { return k.model; }, "terrain model");
}
}  // namespace

std::unique_ptr<TerrainModel> LoadTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                                               const std::vector<std::string>& overrides, const PreparationHooks& hooks) {
  const YamlReader y = YamlReader::LoadWithOverrides(terrain_file, overrides);
  // a model that prepares for long says what it is before it does; any other once it is built
  bool told = false;
  PreparationHooks h = hooks;
  if (hooks.described)
    h.described = [&told, &hooks](const TerrainDescription& d) {
      told = true;
      hooks.described(d);
    };
  std::unique_ptr<TerrainModel> model = FindTerrainKind(y).make(y, vehicle, h);
  if (hooks.described && !told) hooks.described(model->description());
  return model;
}

void CheckTerrainModel(const YamlReader& y, const TerrainVehicle& vehicle) { FindTerrainKind(y).check(y, vehicle); }

void CheckTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                       const std::vector<std::string>& overrides) {
  CheckTerrainModel(YamlReader::LoadWithOverrides(terrain_file, overrides), vehicle);
}

std::unique_ptr<TerrainModel> RestoreTerrainModel(const std::string& terrain_file, const TerrainVehicle& vehicle,
                                                  const std::vector<std::string>& overrides, StateReader& in) {
  const YamlReader y = YamlReader::LoadWithOverrides(terrain_file, overrides);
  const TerrainKind& kind = FindTerrainKind(y);
  if (kind.restore) return kind.restore(y, vehicle, in);
  std::unique_ptr<TerrainModel> m = kind.make(y, vehicle, {});
  m->LoadState(in);
  return m;
}

TerrainDescription DescribeTerrain(const std::string& terrain_file, const std::vector<std::string>& overrides) {
  const YamlReader y = YamlReader::LoadWithOverrides(terrain_file, overrides);
  return FindTerrainKind(y).describe(y);
}

}  // namespace dem_mobility::core
