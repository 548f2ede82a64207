#include "dem_mobility/core/scenes/soil_rig.h"

#include <cstdio>
#include <filesystem>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

void RunSoilRig(SoilRig& rig, const std::function<void(const SoilRig&)>& progress, long every) {
  try {
    while (!rig.done()) {
      rig.Step();
      if (progress && rig.dem().step_count() % every == 0) progress(rig);
    }
  } catch (const SimulationError& e) {
    rig.Fail(e.what());
  }
}

std::chrono::steady_clock::time_point WallClockStartFor(double so_far) {
  return std::chrono::steady_clock::now() -
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(so_far));
}

std::unique_ptr<SoilRig> RigCheckpoints::Start(const YamlReader& scene) {
  const std::string scene_file = o_.scene_file.empty() ? scene.file() : o_.scene_file;
  // what the checkpoints record: the scene, then every input file the rig reads (soil, table)
  InputFileRecord inputs;
  NoteInputFile(scene.file());
  std::unique_ptr<SoilRig> rig = MakeSoilRig(scene);
  if (!o_.restart_file.empty()) {
    restarted_ = ReadCheckpointFile(o_.restart_file, scene_file, o_.overrides,
                                    [&](StateReader& r) { rig->LoadState(r); });
    id_ = restarted_;
  } else {
    id_ = CheckpointIdentity::Of(scene_file, o_.overrides, inputs.Files());
  }
  return rig;
}

void RigCheckpoints::AfterStep(const SoilRig& rig, bool now) {
  if (o_.file.empty()) return;
  const bool first = written_ == 0 && error_.empty() && !restarted();
  // (the clock is read every 256 steps only: this runs after every step)
  if (!now && !first && (rig.dem().step_count() & 255) != 0) return;
  const auto t = std::chrono::steady_clock::now();
  if (!now && !first && std::chrono::duration<double>(t - last_).count() < o_.every) return;
  last_ = t;
  id_.step = rig.dem().step_count();
  id_.time = rig.dem().time();
  try {
    last_bytes_ = WriteCheckpointFile(o_.file, id_, [&rig](StateWriter& w) { rig.SaveState(w); });
    last_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    ++written_;
    written_at_ = id_.time;
  } catch (const ConfigError& e) {  // (the run goes on; its result says the checkpoint failed)
    error_ = e.what();
  }
}

std::string RigCheckpoints::Settle(const SoilRig& rig, ResultFile* f) {
  if (restarted()) {
    f->Set("restarted_from", o_.restart_file);
    f->Set("restarted_at", restarted_.time);
  }
  if (o_.file.empty()) return "";
  f->Set("checkpoints_written", written_);
  if (!error_.empty()) f->Set("checkpoint_error", error_);
  // the checkpoint file holds this run: one it wrote, or the one it was taken up from
  std::error_code ec;
  const bool same = restarted() && std::filesystem::equivalent(o_.restart_file, o_.file, ec);
  const bool holds = written_ > 0 || same;
  const double at = written_ > 0 ? written_at_ : restarted_.time;
  if (!holds) return "";
  if (!rig.done()) {
    f->Set("checkpoint", o_.file);
    f->Set("checkpoint_at", at);
    char line[512];
    std::snprintf(line, sizeof line, "checkpoint kept: %s (t = %.3f s): a restart from it takes the run up from there",
                  o_.file.c_str(), at);
    return line;
  }
  std::remove(o_.file.c_str());
  return "";
}

}  // namespace dem_mobility::core
