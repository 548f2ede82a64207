// A soil rig's checkpoint (scenes/soil_rig.h: RigCheckpoints): a run taken up from a checkpoint
// written in its preparation, or while its tool is in the soil, ends bit for bit as the run that
// never stopped (the cone penetrometer and the single-wheel rig at their tiny levels); the file of
// a run that ended is removed, that of a run that stopped is kept; a checkpoint of another run or
// a damaged one is refused, naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <functional>
#include <string>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/scenes/soil_rig.h"

namespace dem_mobility::core {
namespace {

struct RigCase {
  std::string name, scene;
  std::vector<std::string> overrides;
  std::string prepare_phase;  ///< a checkpoint is written in this phase of the preparation
  std::string tool_phase;     ///< and in this one, with the tool in the soil
};

void PrintTo(const RigCase& c, std::ostream* os) { *os << c.name; }

class RigCheckpoint : public ::testing::TestWithParam<RigCase> {
 protected:
  std::string Path(const std::string& what) const {
    return (std::filesystem::temp_directory_path() /
            ("dm_rig_checkpoint_" + GetParam().name + "_" + what + "_" + std::to_string(::getpid())))
        .string();
  }
  YamlReader Scene(const std::vector<std::string>& more = {}) const {
    std::vector<std::string> o = GetParam().overrides;
    o.insert(o.end(), more.begin(), more.end());
    return YamlReader::LoadWithOverrides(GetParam().scene, o);
  }
  RigCheckpointOptions Options(const std::string& file, const std::string& restart) const {
    RigCheckpointOptions o;
    o.file = file;
    o.restart_file = restart;
    o.overrides = GetParam().overrides;
    return o;
  }
};

/// Steps `rig` until `until` holds, then `more` steps.
void StepUntil(SoilRig& rig, const std::function<bool()>& until, int more) {
  while (!rig.done() && !until()) rig.Step();
  for (int k = 0; k < more && !rig.done(); ++k) rig.Step();
  ASSERT_FALSE(rig.done());
}

void ExpectSameEnd(const SoilRig& a, const SoilRig& b, const std::string& from) {
  ASSERT_TRUE(a.done() && b.done()) << from;
  EXPECT_EQ(a.dem().step_count(), b.dem().step_count()) << from;
  const auto pa = a.dem().positions(), pb = b.dem().positions();
  ASSERT_EQ(pa.size(), pb.size()) << from;
  long differ = 0;
  for (size_t i = 0; i < pa.size(); ++i) differ += (pa[i].array() != pb[i].array()).any();
  EXPECT_EQ(differ, 0) << "particles not where the run that never stopped has them, taken up from " << from;
  // the whole result but the wall time and what it says of checkpoints
  const auto figures = [](const SoilRig& r) {
    ResultFile f = r.Report();
    std::string out;
    std::istringstream in(f.Text());
    for (std::string line; std::getline(in, line);)
      if (line.find("wall_time") == std::string::npos) out += line + "\n";
    return out;
  };
  EXPECT_EQ(figures(a), figures(b)) << "taken up from " << from;
}

TEST_P(RigCheckpoint, TakesTheRunUpBitForBitFromThePreparationAndFromTheToolInTheSoil) {
  const std::string file = Path("run"), in_prep = Path("prep"), in_tool = Path("tool");
  // the run that never stops, with a checkpoint in each phase (copied aside as it is written)
  RigCheckpoints writer(Options(file, ""));
  std::unique_ptr<SoilRig> run = writer.Start(Scene());
  StepUntil(*run, [&] { return run->phase() == GetParam().prepare_phase; }, 50);
  writer.AfterStep(*run, /*now=*/true);
  std::filesystem::copy_file(file, in_prep, std::filesystem::copy_options::overwrite_existing);
  StepUntil(*run, [&] { return run->phase() == GetParam().tool_phase; }, 300);
  writer.AfterStep(*run, /*now=*/true);
  std::filesystem::copy_file(file, in_tool, std::filesystem::copy_options::overwrite_existing);
  RunSoilRig(*run);
  ASSERT_TRUE(run->done());
  ResultFile ended = run->Report();
  writer.Settle(*run, &ended);
  EXPECT_FALSE(std::filesystem::exists(file)) << "the checkpoint of a run that ended is removed";
  EXPECT_EQ(writer.written(), 2);
  EXPECT_TRUE(writer.error().empty()) << writer.error();

  for (const std::string& from : {in_prep, in_tool}) {
    RigCheckpoints reader(Options("", from));
    std::unique_ptr<SoilRig> again = reader.Start(Scene());
    EXPECT_TRUE(reader.restarted());
    RunSoilRig(*again);
    ExpectSameEnd(*run, *again, from);
    ResultFile f = again->Report();
    reader.Settle(*again, &f);
    EXPECT_NE(f.Text().find("restarted_from: " + from), std::string::npos) << f.Text();
  }

  // a run stopped from outside keeps its checkpoint, and its result says where it is
  {
    RigCheckpoints stopping(Options(file, in_tool));
    std::unique_ptr<SoilRig> rig = stopping.Start(Scene());
    for (int k = 0; k < 100; ++k) rig->Step();
    stopping.AfterStep(*rig, /*now=*/true);
    rig->Fail("interrupted: the run was stopped before its end");
    ResultFile f = rig->Report();
    EXPECT_TRUE(stopping.Settle(*rig, &f).find("checkpoint kept") != std::string::npos);
    EXPECT_TRUE(std::filesystem::exists(file));
    EXPECT_NE(f.Text().find("checkpoint: " + file), std::string::npos) << f.Text();
  }

  // refused, naming the checkpoint: another run's (other overrides), a damaged file
  const auto refused = [&](const RigCheckpointOptions& o, const std::vector<std::string>& more, const std::string& word) {
    try {
      RigCheckpoints c(o);
      c.Start(Scene(more));
      ADD_FAILURE() << "accepted " << o.restart_file;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(o.restart_file), std::string::npos) << m;
      EXPECT_NE(m.find(word), std::string::npos) << m;
    }
  };
  RigCheckpointOptions other = Options("", in_tool);
  other.overrides.push_back("seed=2");
  refused(other, {"seed=2"}, "overrides");
  {
    std::fstream f(in_prep, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(200);
    f.put('\x5a');
  }
  refused(Options("", in_prep), {}, "checkpoint");
  for (const std::string& p : {file, in_prep, in_tool}) std::filesystem::remove(p);
}

INSTANTIATE_TEST_SUITE_P(
    Rigs, RigCheckpoint,
    ::testing::Values(RigCase{"cone", DM_CONFIG_DIR "/scenes/cone_penetrometer.yaml",
                              {"fidelity=tiny", "threads=1", "cohesion_factor=2"}, "consolidate", "penetrate"},
                      RigCase{"wheel", DM_CONFIG_DIR "/scenes/single_wheel.yaml",
                              {"fidelity=tiny", "threads=1", "wheel.slip=0.3", "carriage.window=[0.8, 1.1]"},
                              "consolidate", "drive"}),
    [](const ::testing::TestParamInfo<RigCase>& i) { return i.param.name; });

}  // namespace
}  // namespace dem_mobility::core
