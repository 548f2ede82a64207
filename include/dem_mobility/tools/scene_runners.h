// The scenes there are, by their `scene:` key: each reads its file, runs to the end (printing its
// progress and a summary), and returns its result in the one result schema (common/result_file.h).
// dm_run_scene runs any of them; the soil rigs among them also run in the rig nodelet
// (core/scenes/soil_rig.h), the mobility run in the vehicle, terrain and driver nodelets. This is
// the tools' room: the library computes and reports in its result; the console is here.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "dem_mobility/core/common/result_file.h"

namespace dem_mobility::core {

class YamlReader;

struct SceneRunOptions {
  std::string history_file;  ///< mobility runs: the speed history as CSV ("" none)
  bool quiet = false;        ///< no progress lines
  /// Mobility runs and soil rigs: when it turns true (a signal handler sets it) the run ends at the next step
  /// with what it has (status interrupted; the result and history are written).
  const std::atomic<bool>* stop = nullptr;
  /// Mobility runs and soil rigs: the run's checkpoint ("" none), written when the run begins to
  /// step (a mobility run's soil prepared), every `checkpoint_every` wall seconds, and when it is stopped from outside; kept
  /// when the run stops with an error or is interrupted, removed once it has ended (its result
  /// is then what remains). A restart from it goes on bit for bit (common/checkpoint.h).
  std::string checkpoint_file;
  double checkpoint_every = 600.0;  ///< [s] of wall time
  /// Mobility runs and soil rigs: take the run up from this checkpoint ("" from the start); it must be of the
  /// same scene file, overrides, input files and build.
  std::string restart_file;
  /// Mobility runs: the folder of prepared soils ("" none; PreparationHooks::prepared_soil_cache).
  std::string prepared_soil_cache;
  /// What a checkpoint records of the run (and a restart checks): the scene file and the
  /// key=value overrides as given.
  std::string scene_file;
  std::vector<std::string> overrides;
};

struct SceneKind {
  std::string scene;  ///< the `scene:` key
  std::string what;   ///< one line for listings
  /// Reads the scene (ConfigError for bad input) and runs it. A numerical failure does not throw:
  /// the result says status error, with what was measured so far.
  std::function<ResultFile(const YamlReader& scene_file, const SceneRunOptions& options)> run;
  /// Reads and checks the scene and every file it names as `run` does before it starts, and runs
  /// nothing (no soil is prepared): ConfigError for bad input (dm_run_scene --check).
  std::function<void(const YamlReader& scene_file)> check;
};

const std::vector<SceneKind>& SceneKinds();
/// The kind of a scene file (its `scene:` key); ConfigError listing the known kinds otherwise.
const SceneKind& FindSceneKind(const YamlReader& scene_file);

}  // namespace dem_mobility::core
