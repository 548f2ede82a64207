#include "dem_mobility/core/terrain/prepared_soil_cache.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

namespace {
// a prepared soil's file: this line, the format, DemSoilTerrain's state (SealState)
const std::string kSoilMagic = "dem_mobility prepared soil\n";
constexpr uint32_t kSoilFormat = 2;  // 2: the DEM state without its scratch (the plastic pass's, the pair kernels' hot records)
}  // namespace

std::string PreparedSoilCache::PathOf(const YamlReader& y, const std::vector<InputFile>& files,
                                      const TerrainVehicle& vehicle) const {
  std::string key = y.Dump();
  for (const InputFile& f : files) key += "\n" + f.path + " " + std::to_string(f.fingerprint);
  const TriMesh& m = vehicle.tire.soil_mesh;
  key += detail::Concat("\ntire ", vehicle.tire.radius, " ", vehicle.tire.width, " wheels ", vehicle.wheels,
                        " track ", vehicle.track, " wheelbase ", vehicle.wheelbase, " build ", ExecutableFingerprint(),
                        " format ", kSoilFormat);
  uint64_t h = Fnv1a(key.data(), key.size());
  if (!m.vertices.empty()) h = Fnv1a(m.vertices.data(), m.vertices.size() * sizeof(m.vertices[0]), h);
  if (!m.faces.empty()) h = Fnv1a(m.faces.data(), m.faces.size() * sizeof(m.faces[0]), h);
  char name[64];
  std::snprintf(name, sizeof name, "soil_%016llx.prepared", static_cast<unsigned long long>(h));
  return (std::filesystem::path(folder_) / name).string();
}

bool PreparedSoilCache::Read(const std::string& path, const std::function<void(StateReader&)>& load) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return false;
  try {
    const std::string state = OpenSealedState(path, kSoilMagic, kSoilFormat, "prepared soil");
    std::istringstream in(state, std::ios::binary);
    StateReader r(&in, path, state.size());
    load(r);
    if (r.left() != 0) r.Fail(detail::Concat(r.left(), " bytes more than the soil holds"));
    return true;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "dem_soil: the prepared soil does not read (%s): preparing it again\n", e.what());
    return false;
  }
}

void PreparedSoilCache::Keep(const std::string& path, const std::function<void(StateWriter&)>& save) {
  try {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
    std::ostringstream os(std::ios::binary);
    StateWriter w(&os);
    save(w);
    WriteFileAtomically(path, SealState(kSoilMagic, kSoilFormat, os.str()));
  } catch (const ConfigError& e) {  // (the run goes on without the cache)
    std::fprintf(stderr, "dem_soil: the prepared soil is not kept (%s)\n", e.what());
  }
}

}  // namespace dem_mobility::core
