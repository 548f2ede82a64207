#include "dem_mobility/core/cosim/cosim_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

MobilityRunResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver, CoSimObserver* observer) {
  const MobilityRunParams& p = sim.params();
  MobilityRunResult r;
  r.dt = sim.dt();
  r.dt_crit = sim.limit().dt_crit;
  r.dt_limit_element = sim.limit().element;
  r.terrain_model = terrain.description().model;
  r.cone_index = terrain.description().cone_index;
  Vehicle& veh = sim.vehicle();
  const double dt = sim.dt();
  const auto wall0 = std::chrono::steady_clock::now();
  const long drive_step = sim.settle_steps();
  const long run_steps = std::lround(p.duration / dt);
  const long sample_every = std::max(1L, std::lround(1.0 / (p.sample_rate * dt)));
  const long control_every = std::max(1L, std::lround(p.driver.control_period / dt));
  DriverCommand cmd;
  cmd.brake_effort = 1.0;  // settling: brakes on, no drive
  double x0 = 0.0;
  try {
    veh.SetBrakeEffort(cmd.brake_effort);
    veh.SetDriveTorqueRequest(0.0);
    if (observer) observer->OnStep(sim, cmd);
    for (;;) {
      const long k = sim.step() - drive_step;  // steps since the driver's start
      if (k >= 0) {
        if (k == 0) x0 = veh.ChassisFramePosition().x();
        const double t = k * dt;
        const double v = veh.ForwardSpeed();
        const double w_ds = veh.DriveShaftSpeed();
        if (k % control_every == 0) {
          DriverInput in;
          in.step = sim.step();
          in.time = t;
          in.period = control_every * dt;
          in.forward_speed = v;
          in.drive_shaft_speed = w_ds;
          cmd = driver.Exchange(in);
          ++r.driver_updates;
          veh.SetDriveTorqueRequest(cmd.drive_torque);
          veh.SetBrakeEffort(cmd.brake_effort);
        }
        if (k % sample_every == 0) {
          r.history.push_back({t, veh.ChassisFramePosition().x() - x0, v, cmd.speed_command, w_ds,
                               veh.AppliedDriveTorque(), cmd.brake_effort, cmd.wot_limited});
          if (t >= p.plateau.stall_time && v < p.plateau.stall_speed && cmd.speed_command > p.plateau.stall_speed) {
            r.ended_early = true;
            break;
          }
        }
        if (k >= run_steps) break;
      }
      if (observer && observer->StopRequested()) {
        r.interrupted = true;
        break;
      }
      sim.Step(terrain);
      if (observer) observer->OnStep(sim, cmd);
    }
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  r.steps = sim.step();
  r.exchanges = sim.exchanges();
  r.sim_time = r.history.empty() ? 0.0 : r.history.back().t;
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  r.smg = DetectSpeedMadeGood(r.history, p.plateau, p.driver.v_max);
  return r;
}

}  // namespace dem_mobility::core
