#include "dem_mobility/core/mobility/mobility_run.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

namespace {
// a checkpoint file: this line, the format's version, the state (StateWriter), and the Fnv1a of
// all the bytes before it (a damaged file is refused before anything of it is read)
constexpr char kMagic[] = "dem_mobility checkpoint\n";
constexpr uint32_t kFormat = 3;  // 3: the plastic drive (two sums) in place of the largest tension; 2: no scratch
}  // namespace

void CheckpointIdentity::CheckRestart(const std::string& checkpoint, const std::string& scene,
                                      const std::vector<std::string>& ovr) const {
  const std::string who = checkpoint + ": checkpoint of the run of " + scene_file + " at t = " +
                          detail::Concat(driver_time) + " s (step " + std::to_string(step) + "): ";
  std::error_code ec;
  const std::string abs = std::filesystem::absolute(scene, ec).lexically_normal().string();
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

MobilityRun::MobilityRun(const MobilityRunParams& p, const PreparationHooks& hooks)
    : spec_(VehicleSpec::Load(p.vehicle_file)),
      terrain_(LoadTerrainModel(p.terrain_file, TerrainVehicleOf(spec_), p.terrain_overrides, hooks)),
      port_(*terrain_),
      driver_(p.driver, spec_),
      sim_(p, spec_) {
  terrain_->SetGravity(p.Gravity());  // the soil on the grade too
  sim_.Start(port_);
}

MobilityRun::MobilityRun(const MobilityRunParams& p, std::unique_ptr<TerrainModel> terrain)
    : spec_(VehicleSpec::Load(p.vehicle_file)),
      terrain_(std::move(terrain)),
      port_(*terrain_),
      driver_(p.driver, spec_),
      sim_(p, spec_) {
  terrain_->SetGravity(p.Gravity());  // the soil on the grade too
  sim_.Start(port_);
}

MobilityRun::MobilityRun(const MobilityRunParams& p, StateReader& in, CoSimLoopState* loop)
    : spec_(VehicleSpec::Load(p.vehicle_file)),
      terrain_(RestoreTerrainModel(p.terrain_file, TerrainVehicleOf(spec_), p.terrain_overrides, in)),
      port_(*terrain_),
      driver_(p.driver, spec_),
      sim_(p, spec_) {
  // (the soil's gravity, its energy watch and the vehicle's time step are the checkpoint's)
  sim_.Restore(in);
  driver_.Io(in);
  loop->Io(in);
  in.Tag("end");
  if (in.left() != 0) in.Fail(detail::Concat(in.left(), " bytes more than the run holds"));
}

MobilityRunResult MobilityRun::Run(CoSimObserver* observer, const CoSimLoopState* resume) {
  return RunCoSimulation(sim_, port_, driver_, observer, resume);
}

uint64_t MobilityRun::WriteCheckpoint(const std::string& path, CheckpointIdentity id, const CoSimLoopState& loop) const {
  id.step = sim_.step();
  id.driver_time = sim_.driver_time();
  std::ostringstream os(std::ios::binary);
  StateWriter w(&os);
  id.Io(w);
  terrain_->SaveState(w);
  sim_.Save(w);
  const_cast<SceneDriver&>(driver_).Io(w);
  CoSimLoopState st = loop;
  st.r.wall_time = loop.WallTime();
  st.Io(w);
  w.Tag("end");
  const std::string bytes = SealState(kMagic, kFormat, os.str());
  WriteFileAtomically(path, bytes);
  return bytes.size();
}

namespace {
/// The state of a checkpoint file (its header and checksum checked), as bytes.
std::string CheckpointState(const std::string& path) { return OpenSealedState(path, kMagic, kFormat, "checkpoint"); }
}  // namespace

CheckpointIdentity ReadCheckpointIdentity(const std::string& path) {
  const std::string state = CheckpointState(path);
  std::istringstream in(state, std::ios::binary);
  StateReader r(&in, path, state.size());
  CheckpointIdentity id;
  id.Io(r);
  return id;
}

std::string CheckpointIdentity::Describe() const {
  std::ostringstream os;
  os << "scene: " << scene_file << "\noverrides:";
  for (const std::string& o : overrides) os << " " << o;
  os << "\nat: t = " << driver_time << " s (step " << step << ")\n";
  os << "written by this build: " << (executable == ExecutableFingerprint() ? "yes" : "no") << "\ninput files:\n";
  for (const InputFile& f : files) {
    bool ok = false;
    const uint64_t h = FileFingerprint(f.path, &ok);
    os << "  " << f.path << ": " << (!ok ? "cannot be read" : h == f.fingerprint ? "unchanged" : "CHANGED") << "\n";
  }
  return os.str();
}

std::unique_ptr<MobilityRun> MobilityRun::FromCheckpoint(const std::string& path, const MobilityRunParams& p,
                                                         const std::string& scene_file,
                                                         const std::vector<std::string>& overrides,
                                                         CoSimLoopState* loop, CheckpointIdentity* id_out) {
  const std::string state = CheckpointState(path);
  std::istringstream in(state, std::ios::binary);
  StateReader r(&in, path, state.size());
  CheckpointIdentity id;
  id.Io(r);
  id.CheckRestart(path, scene_file, overrides);
  auto run = std::make_unique<MobilityRun>(p, r, loop);
  if (id_out) *id_out = id;
  return run;
}

}  // namespace dem_mobility::core
