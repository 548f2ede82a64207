#include "dem_mobility/core/common/checkpoint.h"

#include <filesystem>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"

namespace dem_mobility::core {

namespace {
// a checkpoint file: this line, the format's version, the state (StateWriter), and the Fnv1a of
// all the bytes before it (a damaged file is refused before anything of it is read)
constexpr char kMagic[] = "dem_mobility checkpoint\n";
constexpr uint32_t kFormat = 3;  // 3: the plastic drive (two sums) in place of the largest tension; 2: no scratch

/// The state of a checkpoint file (its header and checksum checked), as bytes.
std::string CheckpointState(const std::string& path) { return OpenSealedState(path, kMagic, kFormat, "checkpoint"); }

std::string AbsoluteScene(const std::string& scene) {
  std::error_code ec;
  return std::filesystem::absolute(scene, ec).lexically_normal().string();
}
}  // namespace

CheckpointIdentity CheckpointIdentity::Of(const std::string& scene_file, const std::vector<std::string>& overrides,
                                          std::vector<InputFile> files) {
  CheckpointIdentity id;
  id.scene_file = AbsoluteScene(scene_file);
  id.overrides = overrides;
  id.files = std::move(files);
  id.executable = ExecutableFingerprint();
  return id;
}

void CheckpointIdentity::CheckRestart(const std::string& checkpoint, const std::string& scene,
                                      const std::vector<std::string>& ovr) const {
  const std::string who = checkpoint + ": checkpoint of the run of " + scene_file + " at t = " + detail::Concat(time) +
                          " s (step " + std::to_string(step) + "): ";
  const std::string abs = AbsoluteScene(scene);
  if (abs != scene_file) throw ConfigError(who + "it is not a checkpoint of " + abs);
  if (ovr != overrides) {
    std::string was, now;
    for (const std::string& o : overrides) was += " " + o;
    for (const std::string& o : ovr) now += " " + o;
    throw ConfigError(who + "it was run with the overrides [" + was + " ], not [" + now +
                      " ]: a restart takes the same ones");
  }
  if (executable == 0 || ExecutableFingerprint() == 0)
    throw ConfigError(who + "the build that wrote it, or this one, could not be fingerprinted (/proc/self/exe)");
  if (executable != ExecutableFingerprint())
    throw ConfigError(who + "it was written by another build of this program: a restart must run the build that "
                            "wrote it (another may step differently)");
  std::error_code ec;
  for (const InputFile& f : files) {
    if (!std::filesystem::is_regular_file(f.path, ec))
      throw ConfigError(who + "its input file " + f.path + " is not there any more (or is not a file)");
    bool ok = false;
    const uint64_t h = FileFingerprint(f.path, &ok);
    if (!ok) throw ConfigError(who + "its input file " + f.path + " cannot be read any more");
    if (h != f.fingerprint)
      throw ConfigError(who + "its input file " + f.path + " has changed since the run began: a restart goes on only "
                              "with the inputs it began with");
  }
}

std::string CheckpointIdentity::Describe() const {
  std::ostringstream os;
  os << "scene: " << scene_file << "\noverrides:";
  for (const std::string& o : overrides) os << " " << o;
  os << "\nat: t = " << time << " s (step " << step << ")\n";
  os << "written by this build: " << (executable == ExecutableFingerprint() ? "yes" : "no") << "\ninput files:\n";
  for (const InputFile& f : files) {
    bool ok = false;
    const uint64_t h = FileFingerprint(f.path, &ok);
    os << "  " << f.path << ": " << (!ok ? "cannot be read" : h == f.fingerprint ? "unchanged" : "CHANGED") << "\n";
  }
  return os.str();
}

uint64_t WriteCheckpointFile(const std::string& path, const CheckpointIdentity& id,
                             const std::function<void(StateWriter&)>& save) {
  std::ostringstream os(std::ios::binary);
  StateWriter w(&os);
  const_cast<CheckpointIdentity&>(id).Io(w);
  save(w);
  w.Tag("end");
  const std::string bytes = SealState(kMagic, kFormat, os.str());
  WriteFileAtomically(path, bytes);
  return bytes.size();
}

CheckpointIdentity ReadCheckpointIdentity(const std::string& path) {
  const std::string state = CheckpointState(path);
  std::istringstream in(state, std::ios::binary);
  StateReader r(&in, path, state.size());
  CheckpointIdentity id;
  id.Io(r);
  return id;
}

CheckpointIdentity ReadCheckpointFile(const std::string& path, const std::string& scene_file,
                                      const std::vector<std::string>& overrides,
                                      const std::function<void(StateReader&)>& load) {
  const std::string state = CheckpointState(path);
  std::istringstream in(state, std::ios::binary);
  StateReader r(&in, path, state.size());
  CheckpointIdentity id;
  id.Io(r);
  id.CheckRestart(path, scene_file, overrides);
  load(r);
  r.Tag("end");
  if (r.left() != 0) r.Fail(detail::Concat(r.left(), " bytes more than the run holds"));
  return id;
}

}  // namespace dem_mobility::core
