// Command-line runner of core scenes (no ROS): runs a scene file of any kind and prints its result.
//
//   dm_run_scene SCENE.yaml [key=value ...] [--out RESULT.yaml] [--history HISTORY.csv] [--quiet]
//                [--checkpoint FILE [--checkpoint-every SECONDS]] [--restart FILE]
//   dm_run_scene SCENE.yaml [key=value ...] --check     read and check everything, run nothing
//   dm_run_scene --checkpoint-info CHECKPOINT     what a checkpoint holds
//   dm_run_scene --help
// key=value overrides a scene key (dotted for nested keys: driver.kp=4000, grade_deg=12).
// Arguments of the form __name:=value (added by roslaunch) are ignored. Exit status: 0 done, 1 bad
// input (the message names the file and key), 2 usage, 3 a numerical failure during the run (the
// result file, written all the same, holds what was measured), 4 a mobility run or a soil rig
// stopped by SIGINT or SIGTERM (it ends at the next step and its result and history are written,
// status interrupted).
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_run.h"
#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/tools/scene_runners.h"

using namespace dem_mobility::core;

namespace {
std::atomic<bool> g_stop{false};
extern "C" void OnSignal(int) { g_stop.store(true); }

int Usage(std::ostream& os, int status) {
  os << "usage: dm_run_scene SCENE.yaml [key=value ...] [--out RESULT.yaml] [--history HISTORY.csv] [--quiet]\n"
        "                   [--checkpoint FILE [--checkpoint-every SECONDS]] [--restart FILE]\n"
        "                   [--prepared-soil-cache DIR]\n"
        "       dm_run_scene SCENE.yaml [key=value ...] --check\n"
        "       dm_run_scene --checkpoint-info CHECKPOINT\n"
        "       dm_run_scene --help\n"
        "Runs a scene file of any kind (its `scene:` key) without ROS and prints its result.\n"
        "  key=value          overrides a key of the scene (dotted for nested keys: driver.kp=4000, grade_deg=12)\n"
        "  --out FILE         writes the result (YAML) there; checked to be writable before the run\n"
        "  --history FILE     mobility runs: the speed history as CSV\n"
        "  --quiet            no progress lines\n"
        "  --checkpoint FILE  mobility runs and soil rigs (cone_penetrometer, single_wheel): keeps the whole\n"
        "                     run's state in FILE (written when the run begins to step, every\n"
        "                     --checkpoint-every wall seconds, default 600, and on SIGINT or SIGTERM; kept\n"
        "                     after an error or an interrupt, removed once the run has ended)\n"
        "  --restart FILE     mobility runs and soil rigs: takes the run up from that checkpoint, bit for bit\n"
        "                     as if it had never stopped; the same scene, overrides, input files and build\n"
        "                     are required\n"
        "  --prepared-soil-cache DIR  soils prepared before by this build from the same files are read from\n"
        "                     DIR instead of prepared again, and a soil prepared here is kept there\n"
        "                     (default: the environment's DM_SOIL_CACHE; none when unset or empty)\n"
        "  dm_run_scene --checkpoint-info FILE   what a checkpoint holds: its scene, overrides, time, and\n"
        "                     whether this build wrote it and its input files are unchanged\n"
        "  --check            reads and checks the scene and every file it names (vehicle, terrain, soil,\n"
        "                     calibration table), runs nothing, prepares no soil; exit 0 when all is good\n"
        "exit status: 0 done, 1 bad input (the message names file and key), 2 usage, 3 a numerical failure\n"
        "during the run (the result file holds what was measured), 4 interrupted by SIGINT or SIGTERM\n"
        "scenes:";
  for (const SceneKind& k : SceneKinds()) os << "\n  " << k.scene << ": " << k.what;
  os << "\n";
  return status;
}
int Usage() { return Usage(std::cerr, 2); }
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return Usage();
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return Usage(std::cout, 0);
  const std::string scene_file = argv[1];
  if (scene_file == "--checkpoint-info") {
    if (argc != 3) return Usage();
    try {
      std::cout << argv[2] << ":\n" << ReadCheckpointIdentity(argv[2]).Describe();
      return 0;
    } catch (const ConfigError& e) {
      std::cerr << "dm_run_scene: error: " << e.what() << "\n";
      return 1;
    }
  }
  if (scene_file.rfind("--", 0) == 0) return Usage();
  std::string out_file;
  bool check = false;
  SceneRunOptions options;
  options.stop = &g_stop;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  // a file size limit (ulimit -f) fails a write with an error instead of killing the process, so
  // that the result says what failed
  std::signal(SIGXFSZ, SIG_IGN);
  // the test command and a user's shell name a folder of prepared soils once for every run
  if (const char* cache = std::getenv("DM_SOIL_CACHE")) options.prepared_soil_cache = cache;
  std::vector<std::string> overrides;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) out_file = argv[++i];
    else if (a == "--history" && i + 1 < argc) options.history_file = argv[++i];
    else if (a == "--quiet") options.quiet = true;
    else if (a == "--checkpoint" && i + 1 < argc) options.checkpoint_file = argv[++i];
    else if (a == "--restart" && i + 1 < argc) options.restart_file = argv[++i];
    else if (a == "--prepared-soil-cache" && i + 1 < argc) options.prepared_soil_cache = argv[++i];
    else if (a == "--checkpoint-every" && i + 1 < argc) {
      const std::string v = argv[++i];
      char* end = nullptr;
      const double s = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(s >= 1.0 && s <= 1e7)) {
        std::cerr << "dm_run_scene: --checkpoint-every " << v << ": a number of wall seconds in [1, 1e7]\n";
        return 2;
      }
      options.checkpoint_every = s;
    }
    else if (a == "--check") check = true;
    else if (a.rfind("__", 0) == 0 && a.find(":=") != std::string::npos) continue;  // roslaunch's __name:=, __log:=
    else if (a.find('=') != std::string::npos && a.rfind("--", 0) != 0) overrides.push_back(a);
    else return Usage();
  }
  try {
    const YamlReader reader = YamlReader::LoadWithOverrides(scene_file, overrides);
    if (check) {
      const SceneKind& kind = FindSceneKind(reader);
      kind.check(reader);
      std::cout << scene_file << ": ok (" << kind.scene << ": the scene and the files it names read and checked)\n";
      return 0;
    }
    const std::string kind = FindSceneKind(reader).scene;
    if ((!options.checkpoint_file.empty() || !options.restart_file.empty()) && kind != "road_slope" &&
        kind != "soil_slope" && !IsSoilRigScene(kind))
      throw ConfigError(scene_file + ": scene " + kind +
                        ": --checkpoint and --restart are for mobility runs (road_slope, soil_slope) and soil rigs "
                        "(cone_penetrometer, single_wheel)");
    // the results must be writable before the run spends its time on them
    ResultFile::CheckWritable(out_file);
    ResultFile::CheckWritable(options.history_file);
    if (!options.checkpoint_file.empty()) {
      // (its temporary file, not the checkpoint itself: that may be the one --restart reads)
      const std::string probe = options.checkpoint_file + ".writing";
      ResultFile::CheckWritable(probe, "--checkpoint");
      std::remove(probe.c_str());
    }
    options.scene_file = scene_file;
    options.overrides = overrides;
    const ResultFile result = FindSceneKind(reader).run(reader, options);
    if (!out_file.empty()) result.Write(out_file);
    if (result.status() == "error") {
      std::cerr << "dm_run_scene: simulation error: " << result.error() << "\n";
      if (!out_file.empty()) std::cerr << "dm_run_scene: the results so far are in " << out_file << "\n";
      return 3;
    }
    if (result.status() == "interrupted") {
      std::cerr << "dm_run_scene: interrupted" << (out_file.empty() ? "" : "; the results so far are in " + out_file)
                << "\n";
      return 4;
    }
  } catch (const ConfigError& e) {
    std::cerr << "dm_run_scene: error: " << e.what() << "\n";
    return 1;
  } catch (const SimulationError& e) {  // (a scene that keeps no result of a failed run: the pour, the compression)
    std::cerr << "dm_run_scene: simulation error: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {  // (out of memory; an internal check)
    std::cerr << "dm_run_scene: failed: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
