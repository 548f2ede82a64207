// The rigid polygonal road (the paper's CI = 300 case): the tire vertices of each wheel (the
// paper's master surface) against the road's triangles (the slave surface), with the asperity
// friction model. Files: config/terrains/rigid_road.yaml.
#pragma once

#include <memory>

#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

std::unique_ptr<TerrainModel> MakeRoadTerrain(const YamlReader& y, const TerrainVehicle& vehicle);
TerrainDescription DescribeRoadTerrain(const YamlReader& y);
/// Reads and checks the road's keys for `vehicle`, building no mesh.
void CheckRoadTerrain(const YamlReader& y, const TerrainVehicle& vehicle);

}  // namespace dem_mobility::core
