// A soil rig: a soil bed prepared in a container and a tool driven through it (the cone
// penetrometer now, the single-wheel rig next). The rig nodelet and dm_run_scene run any rig the
// same way: step it to its end, show its particles and walls, keep its result.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {

class YamlReader;

class SoilRig {
 public:
  virtual ~SoilRig() = default;
  /// The scene kind (`scene:` of its file).
  virtual const char* kind() const = 0;
  /// One DEM step with the rig's controllers; SimulationError on a numerical failure (the state
  /// stays readable).
  virtual void Step() = 0;
  virtual bool done() const = 0;
  /// Marks the run failed (a SimulationError out of Step(), an interruption).
  virtual void Fail(const std::string& error) = 0;
  virtual const DemSystem& dem() const = 0;
  /// The phase it is in (pour, consolidate, retreat, release, then the rig's own).
  virtual std::string phase() const = 0;
  /// One line on where the run stands (for consoles and displays).
  virtual std::string StatusLine() const = 0;
  /// The walls that move (tools, lid): drawn every frame; the others (the container) once.
  virtual std::vector<int> moving_walls() const = 0;
  /// The result so far (the whole result once done), in the one result schema.
  virtual ResultFile Report() const = 0;
};

/// Steps `rig` to its end; `progress(rig)` every `every` steps. A SimulationError ends the run
/// failed (Fail) with what was measured so far.
void RunSoilRig(SoilRig& rig, const std::function<void(const SoilRig&)>& progress = nullptr, long every = 1000);

/// One kind of rig: its scene kind and how it is built from a scene file.
struct SoilRigKind {
  std::string scene;
  std::function<std::unique_ptr<SoilRig>(const YamlReader& scene_file)> make;
};
const std::vector<SoilRigKind>& SoilRigKinds();
/// True when scenes of `kind` are rigs.
bool IsSoilRigScene(const std::string& kind);
/// Builds the rig of a scene file; ConfigError naming the file and key for bad input.
std::unique_ptr<SoilRig> MakeSoilRig(const YamlReader& scene_file);

}  // namespace dem_mobility::core
