// A run's checkpoint file: which run it holds (CheckpointIdentity) and the run's state
// (common/state_archive.h), sealed with a checksum. Mobility runs (mobility/mobility_run.h) and
// soil rigs (scenes/soil_rig.h) write the same kind of file; a restart goes on only when the scene,
// its overrides, every input file and the build are the ones the run began with.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dem_mobility/core/common/input_files.h"

namespace dem_mobility::core {

class StateReader;
class StateWriter;

/// What a checkpoint says of the run it holds: the scene and overrides it was started with, every
/// input file it read (with the fingerprint of its bytes), the executable that ran it, and where
/// the run was. A restart goes on only with all of them the same, so that the run taken up again
/// is, bit for bit, the run that was written.
struct CheckpointIdentity {
  std::string scene_file;              ///< absolute
  std::vector<std::string> overrides;  ///< key=value, as given
  std::vector<InputFile> files;
  uint64_t executable = 0;             ///< ExecutableFingerprint()
  long step = 0;                       ///< the run's step (the vehicle's, the rig's DEM's)
  /// [s] the run's clock: since the driver's start for a mobility run (< 0: settling), the DEM's
  /// time for a soil rig
  double time = 0.0;
  template <class Ar>
  void Io(Ar& ar) {
    ar.Tag("identity");
    ar(scene_file, overrides, files, executable, step, time);
  }
  /// The identity of a run starting now: `scene_file` made absolute, the overrides, the input
  /// files `files` and this build.
  static CheckpointIdentity Of(const std::string& scene_file, const std::vector<std::string>& overrides,
                               std::vector<InputFile> files);
  /// ConfigError naming `checkpoint` and what differs from the run asked for now (`scene_file`
  /// and `overrides`): another scene or overrides, an input file changed or gone, another build.
  void CheckRestart(const std::string& checkpoint, const std::string& scene_file,
                    const std::vector<std::string>& overrides) const;
  /// What it is, for a person: the scene, the overrides, where the run was, whether this build
  /// wrote it and whether each input file is unchanged.
  std::string Describe() const;
};

/// Writes `id` and then the state `save` writes to `path` through a temporary file (the previous
/// checkpoint stays whole until the new one is); returns the file's size in bytes. ConfigError
/// naming the path.
uint64_t WriteCheckpointFile(const std::string& path, const CheckpointIdentity& id,
                             const std::function<void(StateWriter&)>& save);
/// The identity of the checkpoint `path` (its header and checksum checked; nothing is built).
CheckpointIdentity ReadCheckpointIdentity(const std::string& path);
/// Takes a run up from the checkpoint `path`: checks its identity against the run asked for
/// (CheckpointIdentity::CheckRestart), then `load` reads the state; ConfigError naming the file
/// for anything that does not match, does not read, or is left over. Returns the identity.
CheckpointIdentity ReadCheckpointFile(const std::string& path, const std::string& scene_file,
                                      const std::vector<std::string>& overrides,
                                      const std::function<void(StateReader&)>& load);

}  // namespace dem_mobility::core
