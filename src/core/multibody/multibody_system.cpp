#include "dem_mobility/core/multibody/multibody_system.h"
#include "dem_mobility/core/common/state_archive.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/rotation.h"

namespace dem_mobility::core {

using Eigen::Matrix3d;
using Eigen::Vector3d;

MultibodySystem::MultibodySystem() {
  RigidBody ground;
  ground.name = "ground";
  ground.fixed = true;
  bodies_.push_back(ground);
}

int MultibodySystem::AddBody(RigidBody b) {
  DM_THROW_UNLESS(!finalized_, "body '", b.name, "': cannot add bodies after Finalize()");
  DM_THROW_UNLESS(FindBody(b.name) < 0, "body '", b.name, "' is defined twice");
  if (!b.fixed) {
    DM_THROW_UNLESS(std::isfinite(b.mass) && b.mass > 0.0, "body '", b.name, "': mass ", b.mass,
                    " kg must be positive");
    DM_THROW_UNLESS(b.inertia.allFinite() && (b.inertia - b.inertia.transpose()).norm() <= 1e-9 * b.inertia.norm(),
                    "body '", b.name, "': inertia must be a finite symmetric matrix");
    Eigen::SelfAdjointEigenSolver<Matrix3d> es(b.inertia);
    const Vector3d ev = es.eigenvalues();
    DM_THROW_UNLESS(ev.minCoeff() > 0.0, "body '", b.name, "': inertia is not positive definite (principal moments ",
                    ev.transpose(), " kg m^2)");
    DM_THROW_UNLESS(ev(0) + ev(1) >= ev(2) * (1.0 - 1e-9), "body '", b.name, "': principal moments ", ev.transpose(),
                    " kg m^2 violate the triangle inequality (no physical body has them)");
    b.inv_mass = 1.0 / b.mass;
    b.inv_inertia = b.inertia.inverse();
    b.min_inertia = ev.minCoeff();
  } else {
    b.inv_mass = 0.0;
    b.inv_inertia.setZero();
  }
  b.w_world = b.R * b.w;
  bodies_.push_back(std::move(b));
  return static_cast<int>(bodies_.size()) - 1;
}

int MultibodySystem::FindBody(const std::string& name) const {
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return static_cast<int>(i);
  return -1;
}

TimeStepLimit MultibodySystem::CriticalTimeStep(const std::vector<BodyMode>& extra) const {
  const size_t n = bodies_.size();
  std::vector<double> w2(n, 0.0), zw(n, 0.0), top(n, 0.0);
  std::vector<int> count(n, 0);
  std::vector<std::string> stiffest(n);
  // body b takes the share f of an element's mode (its omega^2 and its damping)
  const auto take = [&](int b, const std::string& name, const StiffnessInfo& s, double f) {
    if (b < 0 || b >= static_cast<int>(n) || bodies_[b].fixed || !(s.omega > 0.0) || !(f > 0.0)) return;
    const double o2 = f * s.omega * s.omega;
    w2[b] += o2;
    zw[b] += f * s.zeta * s.omega;  // the dampers add up as the springs do: 2 zeta_b omega_b = sum 2 zeta_e omega_e
    ++count[b];
    if (o2 > top[b]) {
      top[b] = o2;
      stiffest[b] = name + " (" + s.detail + ")";
    }
  };
  // an element's mode, k |sum_t u_t|^2 with |u_t|^2 <= w_t |q_t|_M^2, is at most k sum_t w_t |q_t|^2 / a_t
  // for any a_t > 0 summing to 1 (Cauchy-Schwarz); with a_t = sqrt(w_t) / sum sqrt(w), body t takes
  // omega^2 sqrt(w_t) sum sqrt(w) / sum w: a light arm on the chassis nearly all of it, the chassis little
  const auto add = [&](int b, const std::string& name, const StiffnessInfo& s) {
    if (s.sides.empty()) return take(b, name, s, 1.0);
    double root = 0.0, total = 0.0;
    for (const auto& [body, w] : s.sides) {
      root += std::sqrt(std::max(0.0, w));
      total += std::max(0.0, w);
    }
    if (!(total > 0.0)) return;
    for (const auto& [body, w] : s.sides)
      if (body == b) take(b, name, s, std::sqrt(std::max(0.0, w)) * root / total);
  };
  const auto pair = [&](const std::string& kind, const std::string& name, int a, int b, const StiffnessInfo& s) {
    add(a, kind + " '" + name + "'", s);
    if (b != a) add(b, kind + " '" + name + "'", s);
  };
  for (const auto& e : point_joints) pair("joint", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : perpendicular_axes) pair("joint", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : orientation_locks) pair("joint", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : line_constraints) pair("joint", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : couplings) {
    const StiffnessInfo s = e.Stiffness(bodies_);
    std::vector<int> seen;  // each body once (its share is the sum of its sides')
    for (const auto& [body, w] : s.sides)
      if (std::find(seen.begin(), seen.end(), body) == seen.end()) seen.push_back(body);
    for (int body : seen) add(body, "coupling '" + e.name + "'", s);
  }
  for (const auto& e : cv_twists) pair("joint", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : springs) pair("spring", e.name, e.a, e.b, e.Stiffness(bodies_));
  for (const auto& e : point_contacts) add(e.body, "contact '" + e.name + "'", e.Stiffness(bodies_));
  for (const BodyMode& m : extra) add(m.body, m.name, m.mode);
  TimeStepLimit lim;
  lim.dt_crit = std::numeric_limits<double>::infinity();
  for (size_t b = 0; b < n; ++b) {
    if (count[b] == 0) continue;
    const double omega = std::sqrt(w2[b]), zeta = zw[b] / omega, dt = CriticalStep(omega, zeta);
    if (dt < lim.dt_crit) {
      lim.dt_crit = dt;
      lim.element = "body '" + bodies_[b].name + "'";
      lim.detail = detail::Concat(count[b], " elements on it together (omega at most ", omega,
                                  " rad/s, damping ratio ", zeta, "), the stiffest ", stiffest[b]);
    }
  }
  return lim;
}

void MultibodySystem::Finalize(double dt, bool check_step) {
  DM_THROW_UNLESS(std::isfinite(dt) && dt > 0.0, "time step dt = ", dt, " s must be positive");
  const TimeStepLimit lim = CriticalTimeStep();
  DM_THROW_UNLESS(!check_step || dt <= lim.dt_crit, "time step dt = ", dt, " s is above the critical step ", lim.dt_crit,
                  " s of ", lim.element, " (", lim.detail, "); use dt <= ", lim.dt_crit,
                  " s or soften that element");
  for (const auto& c : point_contacts) DM_THROW_UNLESS(c.terrain != nullptr, "contact '", c.name, "' has no terrain");
  dt_ = dt;
  finalized_ = true;
  last_ext_force_.assign(bodies_.size(), Vector3d::Zero());
  last_ext_torque_.assign(bodies_.size(), Vector3d::Zero());
  last_source_torque_.assign(torques.size(), 0.0);
  work_ = Work();
  ComputeForces(false);
  e0_ = Energy().Total();
}

void MultibodySystem::ComputeForces(bool accumulate) {
  for (RigidBody& b : bodies_) {
    b.w_world = b.R * b.w;
    b.force = b.mass * gravity_ + b.ext_force;
    b.torque = b.ext_torque;
  }
  if (pre_force_hook) pre_force_hook(*this);
  for (const auto& e : point_joints) e.Apply(bodies_);
  for (const auto& e : perpendicular_axes) e.Apply(bodies_);
  for (const auto& e : orientation_locks) e.Apply(bodies_);
  for (const auto& e : line_constraints) e.Apply(bodies_);
  for (const auto& e : couplings) e.Apply(bodies_);
  for (const auto& e : cv_twists) e.Apply(bodies_);
  for (const auto& e : springs) e.Apply(bodies_);
  for (const auto& e : torques) e.Apply(bodies_);
  for (auto& e : point_contacts) e.Apply(bodies_, step_);
  // the work ledger: the mean of the last and the present evaluation's force times the motion of
  // the step that led here (dt v and dt w at the half step)
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody& b = bodies_[i];
    if (accumulate && !b.fixed)
      work_.external += 0.5 * dt_ * ((last_ext_force_[i] + b.ext_force).dot(b.v) + (last_ext_torque_[i] + b.ext_torque).dot(b.w_world));
    last_ext_force_[i] = b.ext_force;
    last_ext_torque_[i] = b.ext_torque;
  }
  for (size_t k = 0; k < torques.size(); ++k) {
    const AxisTorque& t = torques[k];
    if (!t.source) continue;
    if (accumulate) work_.sources += 0.5 * dt_ * (last_source_torque_[k] + t.torque) * t.RelativeSpeed(bodies_);
    last_source_torque_[k] = t.torque;
  }
  for (RigidBody& b : bodies_) {
    if (b.fixed) continue;
    b.accel = b.inv_mass * b.force;
    const Vector3d t_body = b.R.transpose() * b.torque;
    b.alpha = b.inv_inertia * (t_body - b.w.cross(b.inertia * b.w));  // eq. 2
  }
}

void MultibodySystem::Step() {
  BeginStep();
  EndStep();
}

void MultibodySystem::BeginStep() {
  DM_DEMAND(finalized_);
  const double dt = dt_, h = 0.5 * dt_;
  for (RigidBody& b : bodies_) {
    if (b.fixed) continue;
    b.v += h * b.accel;                 // first half of eq. 3a / 4a
    b.w += h * b.alpha;
    b.x += dt * b.v;                    // x + dt v + dt^2/2 a
    b.R = b.R * ExpRotation(dt * b.w);  // eq. 5 with dtheta = dt w(t + dt/2)
    b.w_world = b.R * b.w;
  }
  for (auto& c : couplings) c.Integrate(bodies_, dt);
  if ((step_ & 63) == 63)
    for (RigidBody& b : bodies_) Reorthonormalize(b.R);
  time_ += dt;
  ++step_;
}

void MultibodySystem::EndStep() {
  const double h = 0.5 * dt_;
  ComputeForces(true);
  for (RigidBody& b : bodies_) {
    if (b.fixed) continue;
    b.v += h * b.accel;  // second half of eq. 3a / 4a
    // the gyroscopic term of eq. 2 at the end of the step: solve w = w_half + h I^-1 (T - w x I w)
    // by fixed-point iteration (keeps the scheme second order for spinning bodies)
    const Vector3d t_body = b.R.transpose() * b.torque;
    const Vector3d w_half = b.w;
    Vector3d w = w_half + h * b.alpha;
    for (int it = 0; it < 3; ++it) w = w_half + h * (b.inv_inertia * (t_body - w.cross(b.inertia * w)));
    b.alpha = b.inv_inertia * (t_body - w.cross(b.inertia * w));
    b.w = w;
  }
  CheckFinite();
}

void MultibodySystem::CheckFinite() const {
  for (const RigidBody& b : bodies_) {
    if (b.fixed) continue;
    if (!(b.x.allFinite() && b.v.allFinite() && b.w.allFinite()))
      throw SimulationError(detail::Concat("step ", step_, " (t = ", time_, " s): body '", b.name,
                                           "' has a non-finite state (x = ", b.x.transpose(), ", v = ",
                                           b.v.transpose(), ", w = ", b.w.transpose(),
                                           "); the time step is too large or an input is NaN"));
  }
}

EnergyReport MultibodySystem::Energy() const {
  EnergyReport e;
  for (const RigidBody& b : bodies_) {
    if (b.fixed) continue;
    e.kinetic += b.KineticEnergy();
    e.gravitational -= b.mass * gravity_.dot(b.x);
  }
  for (const auto& x : point_joints) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : perpendicular_axes) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : orientation_locks) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : line_constraints) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : couplings) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : cv_twists) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : springs) e.elastic += x.PotentialEnergy(bodies_);
  for (const auto& x : point_contacts) e.elastic += x.PotentialEnergy(bodies_);
  return e;
}

double MultibodySystem::TotalMass() const {
  double m = 0.0;
  for (const RigidBody& b : bodies_)
    if (!b.fixed) m += b.mass;
  return m;
}

Vector3d MultibodySystem::CenterOfMass() const {
  Vector3d c = Vector3d::Zero();
  for (const RigidBody& b : bodies_)
    if (!b.fixed) c += b.mass * b.x;
  return c / TotalMass();
}

template <class Ar>
void MultibodySystem::Io(Ar& ar) {
  ar.Tag("multibody");
  ar.Same(static_cast<long>(bodies_.size()), "bodies");
  for (RigidBody& b : bodies_) b.Io(ar);
  ar.Same(static_cast<long>(couplings.size()), "rotational couplings");
  for (RotationalCoupling& c : couplings) ar(c.g);
  ar.Same(static_cast<long>(torques.size()), "axis torques");
  for (AxisTorque& t : torques) ar(t.torque);
  ar.Same(static_cast<long>(line_constraints.size()), "line constraints");
  for (LineConstraint& l : line_constraints) ar(l.target);
  ar.Same(static_cast<long>(point_contacts.size()), "point contacts");
  for (PointSetContact& c : point_contacts) {
    ar(c.history, c.last, c.applied_step);  // (one anchor per point, or none before the first Apply)
  }
  ar(work_, e0_, last_ext_force_, last_ext_torque_, last_source_torque_, gravity_, dt_, time_, step_, finalized_);
  if constexpr (Ar::kLoading) {
    if (last_ext_force_.size() != bodies_.size() || last_ext_torque_.size() != bodies_.size() ||
        last_source_torque_.size() != torques.size())
      ar.Fail("the work ledger's entries do not match the bodies and torques");
    for (const PointSetContact& c : point_contacts)
      if (!c.history.empty() && c.history.size() != c.points.size())
        ar.Fail("a point contact's anchors do not match its points");
  }
}
template void MultibodySystem::Io(StateWriter&);
template void MultibodySystem::Io(StateReader&);

}  // namespace dem_mobility::core
