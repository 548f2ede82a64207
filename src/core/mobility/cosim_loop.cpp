#include "dem_mobility/core/mobility/cosim_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

namespace {

MobilitySample Sample(const VehicleCoSim& sim, double t, const Eigen::Vector3d& from, const DriverCommand& cmd) {
  const Vehicle& veh = sim.vehicle();
  const Eigen::Vector3d at = veh.ChassisFramePosition() - from;
  MobilitySample s{t, at.x(), veh.ForwardSpeed(), cmd.speed_command, veh.DriveShaftSpeed(), veh.AppliedDriveTorque(),
                   cmd.brake_effort, cmd.wot_limited};
  const double r = veh.tire().radius;
  for (int i = 0; i < kWheels; ++i) {
    const WheelState w = veh.GetWheelState(i);
    const double rolling = veh.WheelSpeed(i) * r;
    s.slip[i] = std::abs(rolling) >= 0.05 ? 1.0 - w.velocity.x() / rolling : 0.0;
    const WheelWrench& f = veh.wheel_wrench(i);
    s.sinkage[i] = f.sinkage;
    s.traction += f.force.x();
  }
  s.thrust = veh.AppliedDriveTorque() / veh.driveline_reduction() / r;
  s.y = at.y();
  s.heading = veh.Heading();
  return s;
}

/// The energy watchdog's message.
std::string Unstable(const VehicleCoSim& sim, const LedgerWatch& w) {
  const std::string what = w.finite() ? detail::Concat("the vehicle's energy rose ", -w.least,
                                                       " J above what the terrain and the engine put in (more than ",
                                                       kLedgerTolerance, " of the ", w.Scale(), " J through its ledger)")
                                      : std::string("the vehicle's energy ledger is not finite");
  return detail::Concat("step ", sim.step(), " (t = ", sim.driver_time(), " s): ", what,
                        ": the explicit integration is unstable at dt = ", sim.dt(), " s (the guard's critical step ",
                        sim.limit().dt_crit, " s, ", sim.limit().element, ")");
}

/// The driver's command for the vehicle's state at `t` (since the driver's start; its control
/// period `period`), put on the vehicle.
DriverCommand AskDriver(VehicleCoSim& sim, DriverPort& driver, double t, double period, const Eigen::Vector3d& p0) {
  Vehicle& veh = sim.vehicle();
  DriverInput in;
  in.step = sim.step();
  in.time = t;
  in.period = period;
  in.forward_speed = veh.ForwardSpeed();
  in.drive_shaft_speed = veh.DriveShaftSpeed();
  in.lateral_offset = veh.ChassisFramePosition().y() - p0.y();
  in.heading = veh.Heading();
  const DriverCommand cmd = driver.Exchange(in);
  veh.SetDriveTorqueRequest(cmd.drive_torque);
  veh.SetBrakeEffort(cmd.brake_effort);
  veh.SetSteering(cmd.steering);
  return cmd;
}

}  // namespace

MobilityRunResult RunCoSimulation(VehicleCoSim& sim, TerrainPort& terrain, DriverPort& driver, CoSimObserver* observer,
                                  const CoSimLoopState* resume) {
  const MobilityRunParams& p = sim.params();
  CoSimLoopState st;
  if (resume) {
    st = *resume;
    st.wall_before = resume->r.wall_time;
  }
  st.wall0 = std::chrono::steady_clock::now();
  MobilityRunResult& r = st.r;
  r.dt = sim.dt();
  r.dt_crit = sim.limit().dt_crit;
  r.dt_limit_element = sim.limit().element;
  r.terrain = terrain.description();
  r.coupling_interval = sim.coupling_interval();
  Vehicle& veh = sim.vehicle();
  const double dt = sim.dt();
  const long drive_step = sim.settle_steps();
  const long run_steps = std::lround(p.duration / dt);
  const long sample_every = std::max(1L, std::lround(1.0 / (p.sample_rate * dt)));
  const long control_every = std::max(1L, std::lround(p.driver.control_period / dt));
  DriverCommand& cmd = st.cmd;
  Eigen::Vector3d& p0 = st.p0;  // the chassis frame at the driver's start
  if (!resume) {
    // the watchdog's least scale: the vehicle's weight times its tire radius
    r.vehicle_ledger.floor = veh.system().TotalMass() * 9.81 * veh.tire().radius;
    cmd.brake_effort = 1.0;  // settling: brakes on, no drive
  }
  try {
    if (!resume) {
      veh.SetBrakeEffort(cmd.brake_effort);
      veh.SetDriveTorqueRequest(0.0);
    }
    if (observer) observer->OnStep(sim, cmd);
    for (;;) {
      if (observer) {
        observer->AtStepStart(sim, st);
        if (observer->StopRequested()) {
          r.interrupted = true;
          break;
        }
      }
      const long k = sim.step() - drive_step;  // steps since the driver's start
      if (k >= 0) {
        if (k == 0) p0 = veh.ChassisFramePosition();
        const double t = k * dt;
        const double v = veh.ForwardSpeed();
        if (k % control_every == 0) {
          cmd = AskDriver(sim, driver, t, control_every * dt, p0);
          ++r.driver_updates;
        }
        if (k % sample_every == 0) {
          r.history.push_back(Sample(sim, t, p0, cmd));
          if (v < p.plateau.stall_speed && StalledFor(r.history, p.plateau.stall_speed) >= p.plateau.stall_time) {
            r.ended_early = true;
            break;
          }
          if (p.end_when_steady && t >= p.plateau.window) {
            const std::string s = DetectSpeedMadeGood(r.history, p.plateau, p.driver.v_max).status;
            if (s == "steady" || s == "command_limited") {
              r.ended_early = true;
              break;
            }
          }
        }
        if (k >= run_steps) break;
      }
      if (sim.step() % sample_every == 0) {
        // the energy watchdog: a vehicle whose energy rises past what the terrain and the engine
        // put in is unstable (its dampers cannot give energy): stop, naming the step and the guard
        r.vehicle_ledger.Sample(veh.Energy(), sim.driver_time());
        if (r.vehicle_ledger.Broken(kLedgerTolerance)) throw SimulationError(Unstable(sim, r.vehicle_ledger));
      }
      sim.Step(terrain);
      if (observer) observer->OnStep(sim, cmd);
    }
  } catch (const SimulationError& e) {
    r.error = e.what();
  }
  r.vehicle_energy = veh.Energy();
  r.vehicle_ledger.Sample(r.vehicle_energy, sim.driver_time());
  if (r.vehicle_ledger.Broken(kLedgerTolerance) && r.error.find("the explicit integration is unstable") == std::string::npos)
    // a blow-up in the last samples, or one something else caught first (a wheel thrown off the
    // road): say what it was
    r.error = Unstable(sim, r.vehicle_ledger) + (r.error.empty() ? "" : "; it stopped at: " + r.error);
  r.steps = sim.step();
  r.exchanges = sim.exchanges();
  r.sim_time = r.history.empty() ? 0.0 : r.history.back().t;
  r.wall_time = st.WallTime();
  r.smg = DetectSpeedMadeGood(r.history, p.plateau, p.driver.v_max);
  r.steady = SteadyWindowFigures(r.history, p.plateau.window, veh.system().TotalMass(), p.grade_deg,
                                 p.side_slope_deg);
  return std::move(r);
}

}  // namespace dem_mobility::core
