#include "fuzz_targets.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/soil_law.h"
#include "dem_mobility/core/soil/calibration.h"
#include "dem_mobility/tools/scene_runners.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

#ifndef DM_CONFIG_DIR
#error "DM_CONFIG_DIR must name the shipped config folder"
#endif

namespace dem_mobility::fuzz {
namespace {
using core::YamlReader;

const std::string kConfig = DM_CONFIG_DIR;
const std::string kVehicle = kConfig + "/vehicles/hmmwv/vehicle.yaml";

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The .yaml files of a folder of config/ (not its subfolders: calibration/finest holds no tables), sorted.
std::vector<std::string> FilesOf(const std::string& folder) {
  std::vector<std::string> paths, out;
  for (const auto& e : std::filesystem::directory_iterator(kConfig + "/" + folder))
    if (e.is_regular_file() && e.path().extension() == ".yaml") paths.push_back(e.path().string());
  std::sort(paths.begin(), paths.end());
  for (const std::string& p : paths) out.push_back(ReadFile(p));
  return out;
}

// The text stands for a file in the shipped folder of its kind, so that the paths it names
// (vehicle, terrain, soil, calibration) resolve as in the shipped files.
void Scene(const std::string& text) {
  const YamlReader y = YamlReader::FromString(text, kConfig + "/scenes/fuzz_input.yaml");
  core::FindSceneKind(y).check(y);
}

void Vehicle(const std::string& data) {
  if (data.empty()) return;
  const std::vector<std::string>& files = VehicleFiles();
  const std::string& replaced = files[static_cast<unsigned char>(data[0]) % files.size()];
  const std::string text = data.substr(1);
  core::VehicleSpec::Load(kVehicle, [&](const std::string& path) {
    return path == replaced ? YamlReader::FromString(text, path) : YamlReader::Load(path);
  });
}
std::vector<std::string> VehicleSeeds() {
  std::vector<std::string> out;
  for (size_t i = 0; i < VehicleFiles().size(); ++i) out.push_back(std::string(1, char(i)) + ReadFile(VehicleFiles()[i]));
  return out;
}

void Terrain(const std::string& text) {
  static const core::TerrainVehicle vehicle = core::TerrainVehicleOf(core::VehicleSpec::Load(kVehicle));
  core::CheckTerrainModel(YamlReader::FromString(text, kConfig + "/terrains/fuzz_input.yaml"), vehicle);
}

void Soil(const std::string& text) { core::SoilParams::Read(YamlReader::FromString(text, kConfig + "/soils/fuzz_input.yaml")); }

void Calibration(const std::string& text) {
  core::CiCalibration::Read(YamlReader::FromString(text, kConfig + "/calibration/fuzz_input.yaml"));
}
}  // namespace

void Target::Run(const std::uint8_t* data, std::size_t size) const {
  try {
    read(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const core::ConfigError&) {
  }
}

const std::vector<std::string>& VehicleFiles() {
  static const std::vector<std::string> files = [] {
    std::vector<std::string> f{kVehicle};
    const YamlReader top = YamlReader::Load(kVehicle);
    for (const char* key : {"suspension_front", "suspension_rear", "steering", "driveline", "powertrain", "tire"})
      f.push_back(top.ResolvePath(top.String(key)));
    return f;
  }();
  return files;
}

const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {
      {"scene", "a scene file (config/scenes), checked with the files it names", &Scene, [] { return FilesOf("scenes"); }},
      {"vehicle", "one file of the vehicle (config/vehicles/hmmwv), the first byte choosing which", &Vehicle,
       &VehicleSeeds},
      {"terrain", "a terrain file (config/terrains) checked for the shipped vehicle", &Terrain,
       [] { return FilesOf("terrains"); }},
      {"soil", "a soil file (config/soils)", &Soil, [] { return FilesOf("soils"); }},
      {"calibration", "a cone index calibration table (config/calibration)", &Calibration,
       [] { return FilesOf("calibration"); }},
  };
  return targets;
}

const Target& FindTarget(const std::string& name) {
  for (const Target& t : Targets())
    if (t.name == name) return t;
  throw std::invalid_argument("no fuzz target '" + name + "'");
}

}  // namespace dem_mobility::fuzz
