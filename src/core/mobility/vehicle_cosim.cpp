#include "dem_mobility/core/mobility/vehicle_cosim.h"
#include "dem_mobility/core/common/state_archive.h"

#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

VehicleCoSim::VehicleCoSim(const MobilityRunParams& p, const VehicleSpec& spec) : p_(p) {
  // the chassis frame at x = 0 with the tires just touching the plane z = 0
  vehicle_ = Vehicle::Build(spec, Eigen::Vector3d::Zero());
  MultibodySystem& sys = vehicle_->system();
  // (start_height above that: a drop)
  const Eigen::Vector3d shift(0.0, 0.0, vehicle_->design_ride_height() + p.start_height);
  for (int i = 1; i < sys.num_bodies(); ++i) sys.mutable_body(i).x += shift;
  sys.set_gravity(p.Gravity());
  if (p.start_speed != 0.0) vehicle_->SetRollingSpeed(p.start_speed);
  states_.resize(kWheels);
  wrenches_.resize(kWheels);
}

void VehicleCoSim::Exchange(TerrainPort& terrain) {
  for (int i = 0; i < kWheels; ++i) states_[i] = vehicle_->GetWheelState(i);
  // the terrain advances to the next exchange: one coupling interval of vehicle steps
  terrain.Exchange(step(), time(), dt_ * coupling_, states_, &wrenches_);
  DM_THROW_UNLESS(wrenches_.size() == kWheels, "the terrain answered step ", step(), " with ", wrenches_.size(),
                  " wrenches for ", kWheels, " wheels");
  for (int i = 0; i < kWheels; ++i) {
    const WheelWrench& w = wrenches_[i];
    if (!(w.force.allFinite() && w.moment.allFinite()))
      throw SimulationError(detail::Concat("step ", step(), " (t = ", time(), " s): the terrain's wrench on wheel ",
                                           kWheelNames[i], " is not finite (force ", w.force.transpose(), ")"));
    vehicle_->SetWheelWrench(i, w);
  }
  ++exchanges_;
  last_exchange_ = step();
  CheckContactLimit();
}

void VehicleCoSim::CheckContactLimit() {
  // the contact the terrain reports must stay within the explicit limit of the step in use
  const WheelWrench& w0 = wrenches_[0];
  if (p_.time_step_guard && dt_ > 0.0 && (w0.stiffness != checked_stiffness_ || w0.damping != checked_damping_)) {
    const TimeStepLimit c = vehicle_->CriticalTimeStep(w0.stiffness, w0.damping);
    if (dt_ > c.dt_crit)
      throw SimulationError(detail::Concat("step ", step(), " (t = ", time(), " s): time step ", dt_,
                                           " s is above the critical step ", c.dt_crit, " s of ", c.element, " (",
                                           c.detail, ")"));
    checked_stiffness_ = w0.stiffness;
    checked_damping_ = w0.damping;
  }
}

void VehicleCoSim::Start(TerrainPort& terrain) {
  DM_DEMAND(dt_ == 0.0);
  Exchange(terrain);
  MultibodySystem& sys = vehicle_->system();
  // the vehicle's elements and the terrain's contact on its wheels together
  limit_ = vehicle_->CriticalTimeStep(wrenches_[0].stiffness, wrenches_[0].damping);
  double dt = p_.time_step > 0.0 ? p_.time_step : p_.time_step_safety * limit_.dt_crit;
  int coupling = p_.coupling_interval;
  const double h = terrain.description().time_step;
  if (h > 0.0) {
    if (p_.time_step <= 0.0) {
      const long m = std::max(1L, static_cast<long>(std::ceil(h / dt - 1e-9)));
      dt = h / m;
      coupling = static_cast<int>(m * p_.coupling_interval);
    } else {
      const double ratio = dt * coupling / h;
      const long n = std::lround(ratio);
      if (n < 1 || std::abs(ratio - n) > 1e-6 * ratio)
        throw ConfigError(detail::Concat(p_.file, ": time_step: the exchange interval dt x coupling_interval = ",
                                         dt * coupling, " s is not a whole multiple of the terrain's step ", h, " s (",
                                         terrain.description().file, ", level '", terrain.description().fidelity,
                                         "'); use time_step: auto"));
    }
  }
  if (p_.time_step_guard && !(dt <= limit_.dt_crit))
    throw ConfigError(detail::Concat(p_.file, ": time_step: time step dt = ", dt, " s is above the critical step ",
                                     limit_.dt_crit, " s of ", limit_.element, " (", limit_.detail, "); use dt <= ",
                                     limit_.dt_crit, " s or soften that element"));
  try {
    sys.Finalize(dt, p_.time_step_guard);
  } catch (const ConfigError& e) {
    throw ConfigError(p_.file + ": time_step: " + e.what());
  }
  dt_ = dt;
  coupling_ = coupling;
  checked_stiffness_ = wrenches_[0].stiffness;
  checked_damping_ = wrenches_[0].damping;
  settle_steps_ = std::lround(p_.settle_time / dt_);
}

void VehicleCoSim::Step(TerrainPort& terrain) {
  MultibodySystem& sys = vehicle_->system();
  sys.BeginStep();
  if (sys.step_count() % coupling_ == 0) Exchange(terrain);
  sys.EndStep();
}

template <class Ar>
void VehicleCoSim::Io(Ar& ar) {
  ar.Tag("vehicle_cosim");
  vehicle_->Io(ar);
  ar(dt_, coupling_, limit_, settle_steps_, exchanges_, last_exchange_, checked_stiffness_, checked_damping_, states_,
     wrenches_);
  if constexpr (Ar::kLoading) {
    if (!(dt_ > 0.0) || coupling_ < 1 || settle_steps_ < 0) ar.Fail("the vehicle's time step is not one");
    if (states_.size() != kWheels || wrenches_.size() != kWheels) ar.Fail("the wheels' exchange does not match the wheels");
  }
}

void VehicleCoSim::Restore(StateReader& in) {
  DM_DEMAND(dt_ == 0.0);
  Io(in);
}

void VehicleCoSim::Save(StateWriter& out) const { const_cast<VehicleCoSim*>(this)->Io(out); }

}  // namespace dem_mobility::core
