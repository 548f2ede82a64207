// The scene kinds and how each runs from the command line (dm_run_scene): the console lines of a
// run, its checkpoints and its result file.
#include "dem_mobility/tools/scene_runners.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/registry.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_run.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/dem_pour.h"
#include "dem_mobility/core/scenes/single_wheel.h"
#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/core/scenes/uniaxial_compression.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {
namespace {

/// Prints a progress line at most every `period` seconds of wall time.
class Ticker {
 public:
  explicit Ticker(double period) : period_(period) {}
  bool Due() {
    const double wall = Elapsed();
    if (wall < next_) return false;
    next_ = wall + period_;
    return true;
  }
  double Elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  double period_, next_ = 0.0;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

/// The result of a mobility run that stopped before it began (interrupted or failed while the
/// terrain prepared): the terrain it was (as it described itself once it had read its file), no
/// samples; the history's header is written.
ResultFile BeforeTheRun(const MobilityRunParams& p, const SceneRunOptions& o,
                        std::chrono::steady_clock::time_point wall0, const std::string& status, const std::string& why,
                        const TerrainDescription& terrain) {
  MobilityRunResult r;
  r.interrupted = status == "interrupted";
  if (!r.interrupted) r.error = why;
  r.terrain = terrain;
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  std::printf("%s\n", why.c_str());
  if (!o.history_file.empty()) WriteMobilityHistory(r, o.history_file);
  ResultFile f = MobilityResultFile(r, p);
  f.SetStatus(status, why);
  return f;
}

/// The console and the checkpoints of a mobility run: progress about once a second of wall time,
/// a checkpoint when the run begins to step, every checkpoint_every wall seconds and when it is
/// told to stop.
class MobilityConsole final : public CoSimObserver {
 public:
  MobilityConsole(const MobilityRun& run, const SceneRunOptions& o, const CheckpointIdentity& id, double duration,
                  bool restarted)
      : run_(run), o_(o), id_(id), duration_(duration), restarted_(restarted) {}
  bool StopRequested() override { return o_.stop && o_.stop->load(std::memory_order_relaxed); }
  void AtStepStart(const VehicleCoSim& sim, const CoSimLoopState& st) override {
    if (o_.checkpoint_file.empty()) return;
    // (looked at every 256 steps)
    const bool first = written_ == 0 && !failed_ && !restarted_;
    if (!first && !StopRequested() && ((sim.step() & 255) != 0 || since_.Elapsed() < o_.checkpoint_every)) return;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const uint64_t bytes = run_.WriteCheckpoint(o_.checkpoint_file, id_, st);
      ++written_;
      last_t_ = sim.driver_time();
      std::printf("  checkpoint %s: t = %.3f s, %.1f MB in %.2f s\n", o_.checkpoint_file.c_str(), last_t_,
                  bytes / 1e6, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    } catch (const ConfigError& e) {  // (the run goes on; its result says the checkpoint failed)
      failed_ = true;
      error_ = e.what();
      std::printf("  checkpoint failed: %s\n", e.what());
    }
    std::fflush(stdout);
    since_ = Ticker(0.0);
  }
  void OnStep(const VehicleCoSim& sim, const DriverCommand&) override {
    if (t0_ < 0.0) t0_ = sim.time();  // (the first step this process makes: after a restart, not 0)
    if (o_.quiet || (sim.step() & 255) != 0 || !ticker_.Due()) return;
    const double t = std::max(0.0, sim.driver_time());
    const double rtf = (sim.time() - t0_) / std::max(ticker_.Elapsed(), 1e-9);
    std::printf("  t = %6.2f / %.0f s  speed %6.2f m/s  real-time factor %.2f  ETA %.0f s\n", t, duration_,
                sim.vehicle().ForwardSpeed(), rtf, (duration_ - t) / std::max(rtf, 1e-9));
    std::fflush(stdout);
  }
  int written() const { return written_; }
  double last_t() const { return last_t_; }
  const std::string& error() const { return error_; }

 private:
  const MobilityRun& run_;
  const SceneRunOptions& o_;
  const CheckpointIdentity& id_;
  double duration_;
  bool restarted_;
  double t0_ = -1.0;  ///< the simulated time progress is reckoned from (this process's start)
  Ticker ticker_{1.0};
  Ticker since_{0.0};  ///< since the last checkpoint
  int written_ = 0;
  bool failed_ = false;
  double last_t_ = 0.0;
  std::string error_;
};

/// A mobility run taken up from a checkpoint or built afresh (the terrain prepared), with what a
/// checkpoint of it records. `before` is set instead when it stopped before it began.
struct StartedRun {
  std::unique_ptr<MobilityRun> run;
  CoSimLoopState resume;
  CheckpointIdentity restarted, identity;
  std::optional<ResultFile> before;
};

StartedRun StartMobilityRun(const YamlReader& reader, const MobilityRunParams& p, const SceneRunOptions& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  // what the checkpoints record of the run: the scene (read before this), then every input file
  // the run reads from here on
  InputFileRecord inputs;
  NoteInputFile(reader.file());
  StartedRun s;
  const bool restart = !o.restart_file.empty();
  if (restart) {
    // (ConfigError for a checkpoint of another run, or one that does not read)
    s.run = MobilityRun::FromCheckpoint(o.restart_file, p, o.scene_file.empty() ? reader.file() : o.scene_file,
                                        o.overrides, &s.resume, &s.restarted);
    std::printf("restarted from %s at t = %.3f s (step %ld; %.0f s of wall time before)\n", o.restart_file.c_str(),
                s.restarted.time, s.restarted.step, s.resume.r.wall_time);
  } else {
    TerrainDescription described;  // (what the terrain is, once it has read its file)
    described.file = p.terrain_file;
    try {
      PreparationHooks hooks;
      hooks.stop = [stop = o.stop] { return stop && stop->load(std::memory_order_relaxed); };
      hooks.prepared_soil_cache = o.prepared_soil_cache;
      hooks.described = [&described](const TerrainDescription& d) { described = d; };
      if (!o.quiet)  // (a soil at a fine level prepares for minutes to hours)
        hooks.progress = [](const PreparationProgress& at) {
          std::printf("  preparing the terrain: %s\n", at.Line().c_str());
          std::fflush(stdout);
        };
      s.run = std::make_unique<MobilityRun>(p, hooks);
    } catch (const Interrupted& e) {
      // stopped while the terrain prepared, before the run began: the result and the history (its
      // header) say so, the result with how far the preparation had come
      s.before = BeforeTheRun(p, o, wall0, "interrupted", e.what(), described);
      return s;
    } catch (const SimulationError& e) {
      // a numerical failure in the terrain's preparation or the opening exchange (a watchdog): the
      // result says so, as a failure during a run does
      s.before = BeforeTheRun(p, o, wall0, "error", e.what(), described);
      return s;
    }
  }
  CheckpointIdentity& id = s.identity;
  id.scene_file = restart ? s.restarted.scene_file
                          : std::filesystem::absolute(o.scene_file.empty() ? reader.file() : o.scene_file)
                                .lexically_normal()
                                .string();
  id.overrides = o.overrides;
  id.files = restart ? s.restarted.files : inputs.Files();
  id.executable = ExecutableFingerprint();
  return s;
}

/// The history and, with a moving patch, its checks of the soil ahead (<history>.patch_checks.csv).
void WriteMobilityFiles(MobilityRunResult* r, const MobilityRun& run, const SceneRunOptions& o) {
  try {
    if (o.history_file.empty()) return;
    WriteMobilityHistory(*r, o.history_file);
    const auto* soil = dynamic_cast<const DemSoilTerrain*>(&run.terrain());
    if (soil && soil->patch()) {
      const std::string& h = o.history_file;
      const size_t dot = h.rfind(".csv");
      WritePatchChecks(soil->patch()->stats(),
                       (dot != std::string::npos && dot + 4 == h.size() ? h.substr(0, dot) : h) + ".patch_checks.csv");
    }
  } catch (const ConfigError& e) {  // the run is kept: its result says what failed
    if (r->error.empty()) r->error = e.what();
  }
}

/// What the result says of the checkpoints; the checkpoint is kept for a restart after an error or
/// an interrupt, and removed once the run has ended (its result is then what remains).
void SettleCheckpoint(ResultFile* f, const MobilityRunResult& r, const SceneRunOptions& o,
                      const MobilityConsole& console, const StartedRun& s) {
  const bool restart = !o.restart_file.empty();
  if (restart) {
    f->Set("restarted_from", o.restart_file);
    f->Set("restarted_at", s.restarted.time);
  }
  if (o.checkpoint_file.empty()) return;
  f->Set("checkpoints_written", console.written());
  if (!console.error().empty()) f->Set("checkpoint_error", console.error());
  // the checkpoint file holds this run: one it wrote, or the one it was taken up from
  std::error_code ec;
  const bool same = restart && std::filesystem::equivalent(o.restart_file, o.checkpoint_file, ec);
  const bool holds = console.written() > 0 || same;
  const double at = console.written() > 0 ? console.last_t() : s.restarted.time;
  const std::string status = r.Status();
  if (status == "error" || status == "interrupted") {
    if (holds) {
      f->Set("checkpoint", o.checkpoint_file);
      f->Set("checkpoint_at", at);
      std::printf("checkpoint kept: %s (t = %.3f s): --restart %s takes the run up from there\n",
                  o.checkpoint_file.c_str(), at, o.checkpoint_file.c_str());
    }
  } else if (holds) {
    std::remove(o.checkpoint_file.c_str());
  }
}

ResultFile RunMobilityScene(const YamlReader& reader, const SceneRunOptions& o) {
  const MobilityRunParams p = MobilityRunParams::Read(reader);
  StartedRun s = StartMobilityRun(reader, p, o);
  if (s.before) return *s.before;
  MobilityRun& run = *s.run;
  const TimeStepLimit& lim = run.sim().limit();
  std::printf("scene %s: grade %.1f deg, %d bodies, dt %.3g s (critical %.3g s, %s), %.1f s simulated\n",
              p.file.c_str(), p.grade_deg, run.vehicle().system().num_bodies() - 1, run.dt(), lim.dt_crit,
              lim.element.c_str(), p.duration);
  std::fflush(stdout);
  const bool restart = !o.restart_file.empty();
  MobilityConsole console(run, o, s.identity, p.duration, restart);
  MobilityRunResult r = run.Run(&console, restart ? &s.resume : nullptr);
  WriteMobilityFiles(&r, run, o);
  std::printf("speed_made_good: %.3f m/s (%.2f mph), status %s, window slope %.4f m/s^2\n", r.smg.value,
              r.smg.value / 0.44704, r.smg.status.c_str(), r.smg.window_slope);
  std::printf("run: %ld steps, %.2f s simulated in %.2f s wall (real-time factor %.2f)\n", r.steps, r.sim_time,
              r.wall_time, r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0);
  ResultFile f = MobilityResultFile(r, p, {}, &run.terrain());
  SettleCheckpoint(&f, r, o, console, s);
  return f;
}

void CheckMobilityScene(const YamlReader& reader) {
  const MobilityRunParams p = MobilityRunParams::Read(reader);
  const VehicleSpec spec = VehicleSpec::Load(p.vehicle_file);
  CheckTerrainModel(p.terrain_file, TerrainVehicleOf(spec), p.terrain_overrides);
}

ResultFile RunPourScene(const YamlReader& reader, const SceneRunOptions&) {
  const DemPourParams p = DemPourParams::Read(reader);
  std::printf("scene %s: %d particles of %.3g m in a %.3g x %.3g m box, dt %.3g s, %d thread(s)\n", p.file.c_str(),
              p.particles, p.soil.diameter, p.box_length, p.box_width, p.time_step, p.threads);
  std::fflush(stdout);
  const DemPourResult r = RunDemPour(p);
  std::printf("poured: height %.4f m, bulk density %.1f kg/m^3\n", r.height_poured, r.density_poured);
  std::printf("lid: %.1f kPa held; released: height %.4f m, bulk density %.1f kg/m^3, mean plastic strain %.4f\n",
              r.lid_pressure_reached * 1e-3, r.height_consolidated, r.density_consolidated, r.mean_plastic_strain);
  std::printf("run: %ld steps, %.3f s simulated in %.1f s wall (%.2f M particle-steps/s)\n", r.steps, r.sim_time,
              r.wall_time, r.wall_time > 0 ? 1e-6 * r.particles * r.steps / r.wall_time : 0.0);
  return DemPourResultFile(r, p);
}

/// A soil rig of the scene, built afresh or taken up from a checkpoint, stepped to its end with its
/// console lines and checkpoints; a stop from outside ends it interrupted, its checkpoint written
/// first. Returns its result, with what it says of the checkpoints.
ResultFile RunRig(const YamlReader& reader, const SceneRunOptions& o,
                  const std::function<void(const SoilRig&)>& summary) {
  RigCheckpointOptions c;
  c.file = o.checkpoint_file;
  c.every = o.checkpoint_every;
  c.restart_file = o.restart_file;
  c.scene_file = o.scene_file;
  c.overrides = o.overrides;
  RigCheckpoints checkpoints(c);
  const std::unique_ptr<SoilRig> rig = checkpoints.Start(reader);
  if (checkpoints.restarted())
    std::printf("restarted from %s at t = %.3f s (step %ld), phase %s\n", o.restart_file.c_str(),
                checkpoints.identity().time, checkpoints.identity().step, rig->phase().c_str());
  std::fflush(stdout);
  Ticker ticker(2.0);
  try {
    while (!rig->done()) {
      if (o.stop && o.stop->load(std::memory_order_relaxed)) {
        checkpoints.AfterStep(*rig, /*now=*/true);
        rig->Fail("interrupted: the run was stopped before its end");
        break;
      }
      rig->Step();
      const int written = checkpoints.written();
      checkpoints.AfterStep(*rig);
      if (checkpoints.written() > written && !o.quiet) {
        std::printf("  checkpoint %s: t = %.3f s, %.1f MB in %.2f s\n", o.checkpoint_file.c_str(), checkpoints.last_time(),
                    checkpoints.last_bytes() / 1e6, checkpoints.last_seconds());
        std::fflush(stdout);
      }
      if (!o.quiet && rig->dem().step_count() % 500 == 0 && ticker.Due()) {
        std::printf("  %7.1f s wall  %s\n", ticker.Elapsed(), rig->StatusLine().c_str());
        std::fflush(stdout);
      }
    }
  } catch (const SimulationError& e) {
    rig->Fail(e.what());
  }
  summary(*rig);
  ResultFile f = rig->Report();
  const std::string line = checkpoints.Settle(*rig, &f);
  if (!line.empty()) std::printf("%s\n", line.c_str());
  if (!checkpoints.error().empty()) std::printf("checkpoint failed: %s\n", checkpoints.error().c_str());
  return f;
}

ResultFile RunConeScene(const YamlReader& reader, const SceneRunOptions& o) {
  const ConeParams p = ConeParams::Read(reader);
  std::printf("scene %s: level '%s', f %.4g, mu %.3g, %d particles of %.3g m in a %.3g m container, cone at %.3g m/s, "
              "dt %.3g s, %d thread(s)\n",
              p.file.c_str(), p.level.name.c_str(), p.strength.cohesion_factor, p.friction, p.ParticleCount(),
              p.level.particle_diameter, p.level.container_diameter, p.level.cone_speed, p.level.time_step, p.threads);
  return RunRig(reader, o, [&p](const SoilRig& rig) {
    const ConeResult r = static_cast<const ConePenetrometer&>(rig).Result();
    std::printf("prepared: surface %.3f m, bulk density %.1f -> %.1f kg/m^3, lid %.1f kPa held\n", r.surface_height,
                r.density_poured, r.density_consolidated, r.lid_pressure_reached * 1e-3);
    std::printf("cone_index: %.2f psi (std %.2f, trend %.1f psi/m over tip depths %.3g-%.3g m, %d samples); cone speed "
                "%.4f-%.4f m/s\n",
                r.cone_index_psi, r.cone_index_std_psi, r.cone_index_trend_psi_per_m, p.level.ci_from, p.level.ci_to,
                r.window_samples, r.speed_min, r.speed_max);
    std::printf("run: %ld steps, %.3f s simulated (%.3f s preparation) in %.1f s wall\n", r.steps, r.sim_time,
                r.prep_time, r.wall_time);
  });
}

ResultFile RunSingleWheelScene(const YamlReader& reader, const SceneRunOptions& o) {
  const SingleWheelParams p = SingleWheelParams::Read(reader);
  const SoilBinLevel& l = p.bin.level;
  std::printf("scene %s: level '%s', f %.4g, mu %.3g, %d particles of %.3g m in a %.3g x %.3g m bin, dt %.3g s, "
              "%d thread(s); wheel %s, load %.0f kg, carriage %.3g m/s\n",
              p.file.c_str(), l.name.c_str(), p.bin.strength.cohesion_factor, p.bin.friction, p.bin.ParticleCount(),
              l.particle_diameter, l.length, l.width, l.time_step, p.bin.threads,
              p.drive == SingleWheelParams::Drive::kSlip ? ("at slip " + std::to_string(p.slip)).c_str()
                                                          : SingleWheelParams::DriveName(p.drive),
              p.load_mass, p.speed);
  return RunRig(reader, o, [&p](const SoilRig& r) {
    const auto& rig = static_cast<const SingleWheelRig&>(r);
    const SingleWheelRig::Window w = rig.Measured();
    const double W = p.Weight(), R = p.tire.radius;
    std::printf("prepared: surface %.3f m, lid %.1f kPa held\n", rig.bin().surface_height(),
                rig.bin().preparation().lid_pressure_reached() * 1e-3);
    std::printf("window %.2f-%.2f m (%d samples): DP/W %.4f (std %.4f), T/(Wr) %.4f (std %.4f), sinkage %.4f m "
                "(std %.4f), slip %.4f\n",
                p.window_from, p.window_to, w.samples, w.dp / W, w.dp_std / W, w.torque / (W * R),
                w.torque_std / (W * R), w.sinkage, w.sinkage_std, w.slip);
    std::printf("run: %ld steps, %.3f s simulated in %.1f s wall (%.1f s preparation)\n", rig.dem().step_count(),
                rig.dem().time(), rig.wall_time(), rig.preparation_wall_time());
  });
}

ResultFile RunCompressionScene(const YamlReader& reader, const SceneRunOptions&) {
  const CompressionParams p = CompressionParams::Read(reader);
  std::printf("scene %s: %.3g m particles in a %.3g m cylinder, f %.3g, dt %.3g s\n", p.file.c_str(),
              p.particle_diameter, p.cylinder_diameter, p.soil.cohesion_factor, p.time_step);
  std::fflush(stdout);
  const CompressionResult r = RunUniaxialCompression(p);
  std::printf("poured: %.1f kg/m^3 (%d particles)\n", r.density_poured, r.particles);
  for (const CompressionPoint& c : r.loading)
    std::printf("  loading   %8.1f kPa  %7.1f kg/m^3\n", c.pressure * 1e-3, c.density);
  for (const CompressionPoint& c : r.unloading)
    std::printf("  unloading %8.1f kPa  %7.1f kg/m^3\n", c.pressure * 1e-3, c.density);
  std::printf("released: %.1f kg/m^3; %.3f s simulated in %.1f s wall\n", r.density_released, r.sim_time, r.wall_time);
  return CompressionResultFile(r, p);
}

}  // namespace

const std::vector<SceneKind>& SceneKinds() {
  static const std::vector<SceneKind> kinds = {
      {"road_slope", "the vehicle accelerating up a grade on a terrain: speed-made-good", &RunMobilityScene,
       &CheckMobilityScene},
      {"soil_slope", "the vehicle accelerating up a grade on a moving DEM soil patch: speed-made-good", &RunMobilityScene,
       &CheckMobilityScene},
      {"dem_pour", "soil preparation: pour, settle, consolidate with a lid, release", &RunPourScene,
       [](const YamlReader& y) { DemPourParams::Read(y); }},
      {"cone_penetrometer", "the cone penetrometer: cone index of a prepared soil", &RunConeScene,
       [](const YamlReader& y) { ConeParams::Read(y); }},
      {"uniaxial_compression", "piston-cylinder compression: bulk density against pressure", &RunCompressionScene,
       [](const YamlReader& y) { CompressionParams::Read(y); }},
      {"single_wheel", "the single-wheel rig: drawbar pull, torque and sinkage of a tire on DEM soil at a slip",
       &RunSingleWheelScene, [](const YamlReader& y) { SingleWheelParams::Read(y); }},
  };
  return kinds;
}

const SceneKind& FindSceneKind(const YamlReader& y) {
  return FindKind(y, "scene", SceneKinds(), [](const SceneKind& k) { return k.scene; }, "scene");
}

}  // namespace dem_mobility::core
