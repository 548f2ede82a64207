// A mobility run in one process: the vehicle, the scene's terrain model and its driver called
// directly, through the same loop the nodelets run (mobility/cosim_loop.h).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/checkpoint.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/mobility/cosim_loop.h"
#include "dem_mobility/core/terrain/terrain_model.h"

namespace dem_mobility::core {

class StateReader;

class MobilityRun {
 public:
  /// Builds the terrain, the driver and the vehicle, and makes the opening exchange (ConfigError
  /// for bad input or a time step above the limit). `hooks` are called while the terrain prepares
  /// (PreparationHooks): once `stop` returns true, Interrupted says where the preparation was.
  explicit MobilityRun(const MobilityRunParams& p, const PreparationHooks& hooks = {});
  /// The same on a terrain built already (e.g. a copy of a prepared soil: one preparation, many runs).
  MobilityRun(const MobilityRunParams& p, std::unique_ptr<TerrainModel> terrain);
  /// The run of a checkpoint, after its identity (ReadCheckpoint): the terrain restored without
  /// its preparation, the vehicle, the driver and the loop state (`*loop`) as written.
  MobilityRun(const MobilityRunParams& p, StateReader& in, CoSimLoopState* loop);
  /// `resume`: the loop state a checkpoint gave (then the run goes on where it was).
  MobilityRunResult Run(CoSimObserver* observer = nullptr, const CoSimLoopState* resume = nullptr);
  /// Writes the whole run (`id` with the vehicle's step filled in, the terrain, the vehicle, the
  /// driver, the loop state `loop`) to `path` through a temporary file (the previous checkpoint
  /// stays whole until the new one is); returns its size in bytes. ConfigError naming the path.
  uint64_t WriteCheckpoint(const std::string& path, CheckpointIdentity id, const CoSimLoopState& loop) const;
  VehicleCoSim& sim() { return sim_; }
  Vehicle& vehicle() { return sim_.vehicle(); }
  TerrainPort& terrain_port() { return port_; }
  const TerrainModel& terrain() const { return *terrain_; }
  TerrainModel& mutable_terrain() { return *terrain_; }
  double dt() const { return sim_.dt(); }

  /// A checkpoint's run taken up again: reads `path`'s identity, checks it against the run asked
  /// for (CheckpointIdentity::CheckRestart), and builds the run from the rest (ConfigError naming
  /// the file for anything that does not match or does not read).
  static std::unique_ptr<MobilityRun> FromCheckpoint(const std::string& path, const MobilityRunParams& p,
                                                     const std::string& scene_file,
                                                     const std::vector<std::string>& overrides,
                                                     CoSimLoopState* loop, CheckpointIdentity* id = nullptr);

 private:
  VehicleSpec spec_;  ///< read once: the terrain, the driver and the vehicle take what they need
  std::unique_ptr<TerrainModel> terrain_;
  LocalTerrainPort port_;
  SceneDriver driver_;
  VehicleCoSim sim_;
};

}  // namespace dem_mobility::core
