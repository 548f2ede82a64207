// The soil rigs there are (soil_rig.h: SoilRigKinds): apart from the interface, so that the rigs
// include the interface and only the registry includes the rigs.
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/registry.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/single_wheel.h"
#include "dem_mobility/core/scenes/soil_rig.h"

namespace dem_mobility::core {

const std::vector<SoilRigKind>& SoilRigKinds() {
  static const std::vector<SoilRigKind> kinds = {
      {"cone_penetrometer",
       [](const YamlReader& y) { return std::make_unique<ConePenetrometer>(ConeParams::Read(y)); }},
      {"single_wheel",
       [](const YamlReader& y) { return std::make_unique<SingleWheelRig>(SingleWheelParams::Read(y)); }},
  };
  return kinds;
}

bool IsSoilRigScene(const std::string& kind) {
  for (const SoilRigKind& k : SoilRigKinds())
    if (k.scene == kind) return true;
  return false;
}

std::unique_ptr<SoilRig> MakeSoilRig(const YamlReader& y) {
  return FindKind(y, "scene", SoilRigKinds(), [](const SoilRigKind& k) { return k.scene; }, "soil rig").make(y);
}

}  // namespace dem_mobility::core
