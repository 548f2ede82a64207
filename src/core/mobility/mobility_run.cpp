#include "dem_mobility/core/mobility/mobility_run.h"

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {

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
}

MobilityRunResult MobilityRun::Run(CoSimObserver* observer, const CoSimLoopState* resume) {
  return RunCoSimulation(sim_, port_, driver_, observer, resume);
}

uint64_t MobilityRun::WriteCheckpoint(const std::string& path, CheckpointIdentity id, const CoSimLoopState& loop) const {
  id.step = sim_.step();
  id.time = sim_.driver_time();
  return WriteCheckpointFile(path, id, [&](StateWriter& w) {
    terrain_->SaveState(w);
    sim_.Save(w);
    const_cast<SceneDriver&>(driver_).Io(w);
    CoSimLoopState st = loop;
    st.r.wall_time = loop.WallTime();
    st.Io(w);
  });
}

std::unique_ptr<MobilityRun> MobilityRun::FromCheckpoint(const std::string& path, const MobilityRunParams& p,
                                                         const std::string& scene_file,
                                                         const std::vector<std::string>& overrides,
                                                         CoSimLoopState* loop, CheckpointIdentity* id_out) {
  std::unique_ptr<MobilityRun> run;
  const CheckpointIdentity id = ReadCheckpointFile(path, scene_file, overrides, [&](StateReader& r) {
    run = std::make_unique<MobilityRun>(p, r, loop);
  });
  if (id_out) *id_out = id;
  return run;
}

}  // namespace dem_mobility::core
