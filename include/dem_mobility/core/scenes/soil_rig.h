// A soil rig: a soil bed prepared in a container and a tool driven through it (the cone
// penetrometer now, the single-wheel rig next). The rig nodelet and dm_run_scene run any rig the
// same way: step it to its end, show its particles and walls, keep its result.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/checkpoint.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {

class StateReader;
class StateWriter;
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
  /// Its state in a checkpoint (common/checkpoint.h): everything its next steps depend on, so that
  /// a rig built from the same scene and loaded with it steps on bit for bit, at any phase.
  virtual void SaveState(StateWriter& out) const = 0;
  /// Reads what SaveState wrote into a rig built from the same scene; ConfigError (through `in`)
  /// when it is not the state of such a rig.
  virtual void LoadState(StateReader& in) = 0;
};

/// Steps `rig` to its end; `progress(rig)` every `every` steps. A SimulationError ends the run
/// failed (Fail) with what was measured so far.
void RunSoilRig(SoilRig& rig, const std::function<void(const SoilRig&)>& progress = nullptr, long every = 1000);

/// The start of a rig's wall clock that makes its wall time `so_far` seconds now: a rig taken up
/// from a checkpoint goes on counting from the wall time the checkpoint holds.
std::chrono::steady_clock::time_point WallClockStartFor(double so_far);

/// Where a rig run keeps its checkpoint, and whether it is taken up from one.
struct RigCheckpointOptions {
  std::string file;          ///< the checkpoint ("" none)
  double every = 600.0;      ///< [s] of wall time between checkpoints
  std::string restart_file;  ///< take the run up from this checkpoint ("" from the start)
  /// What a checkpoint records of the run (and a restart checks): the scene file as given ("" the
  /// scene reader's file) and the key=value overrides it was read with.
  std::string scene_file;
  std::vector<std::string> overrides;
};

/// The checkpoints of one rig run, for every way a rig runs (dm_run_scene, the rig nodelet): the
/// rig built afresh or taken up from a checkpoint, a checkpoint once it steps, every `every`
/// seconds of wall time and when it is stopped from outside, and what becomes of the file at the
/// end: kept when the run failed or was interrupted (a restart takes it up), removed once it has
/// ended (its result is then what remains).
class RigCheckpoints {
 public:
  explicit RigCheckpoints(RigCheckpointOptions o) : o_(std::move(o)) {}
  /// The rig of `scene` (MakeSoilRig), then, with a restart file, its state from it: ConfigError
  /// naming the checkpoint when it is not one of this run (another scene, overrides, input file
  /// or build) or does not read.
  std::unique_ptr<SoilRig> Start(const YamlReader& scene);
  /// After a step: writes the checkpoint when one is due (after the first step of a run started
  /// afresh, then every `every` s, looked at every 256 steps) or `now`. A checkpoint that cannot be
  /// written does not stop the run: error() says why, and the result will.
  void AfterStep(const SoilRig& rig, bool now = false);
  /// At the run's end (done or failed): the result's figures of the checkpoints (restarted_from,
  /// restarted_at, checkpoints_written, checkpoint, checkpoint_at, checkpoint_error), the file
  /// kept or removed. Returns a line for a console ("" none).
  std::string Settle(const SoilRig& rig, ResultFile* f);
  int written() const { return written_; }
  /// The last checkpoint written: its size [bytes], how long the writing took [s], the rig's time in it [s].
  uint64_t last_bytes() const { return last_bytes_; }
  double last_seconds() const { return last_seconds_; }
  double last_time() const { return written_at_; }
  const std::string& error() const { return error_; }
  bool restarted() const { return !o_.restart_file.empty(); }
  const CheckpointIdentity& identity() const { return id_; }

 private:
  RigCheckpointOptions o_;
  CheckpointIdentity id_, restarted_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  int written_ = 0;
  double written_at_ = 0.0;  ///< [s] the rig's time in the last checkpoint written
  uint64_t last_bytes_ = 0;
  double last_seconds_ = 0.0;
  std::string error_;
};

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
