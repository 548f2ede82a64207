#include "dem_mobility/core/scenes/cone_penetrometer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/soil/soil_prep.h"

namespace dem_mobility::core {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

ConeLevel ReadLevel(const YamlReader& y, const std::string& name) {
  ConeLevel l;
  l.name = name;
  l.particle_diameter = y.DoubleIn("particle_diameter", 0.005, 0.5);
  l.container_diameter = y.DoubleIn("container_diameter", 0.1, 20.0);
  l.soil_depth = y.DoubleIn("soil_depth", 0.05, 20.0);
  l.cone_speed = y.DoubleIn("cone_speed", 1e-3, 5.0);
  if (y.Has("approach_depth") || y.Has("approach_speed")) {
    l.approach_depth = y.DoubleIn("approach_depth", 0.0, 20.0);
    l.approach_speed = y.DoubleIn("approach_speed", 1e-3, 5.0);
  }
  l.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  l.settle_time = y.DoubleIn("settle_time", 0.0, 100.0);
  l.hold_time = y.DoubleIn("hold_time", 0.0, 100.0);
  const std::vector<double> w = y.DoubleList("ci_window");
  if (w.size() != 2 || !(w[0] >= 0.0 && w[1] > w[0]))
    y.Fail("ci_window", "must be [from, to] tip depths below the surface with 0 <= from < to");
  l.ci_from = w[0];
  l.ci_to = w[1];
  y.Finish();
  return l;
}

}  // namespace

ConeParams ConeParams::Read(const YamlReader& y) {
  ConeParams p;
  p.file = y.file();
  p.soil = ReadSceneSoil(y, "cone_penetrometer");
  p.level = ReadFidelityLevel<ConeLevel>(y, ReadLevel);  // every level checked, the named one used
  // the soil: f directly, or from a requested cone index through the table of the level's
  // particle size and the friction (CI(f) depends on both)
  p.friction = y.DoubleIn("friction", 0.0, 2.0);
  p.strength = SoilStrength::Read(y, p.level.particle_diameter, p.friction, /*name_ci_of_f=*/false);
  p.soil.diameter = p.level.particle_diameter;
  p.soil.cohesion_factor = p.strength.cohesion_factor;
  p.soil.friction = p.friction;
  p.threads = ReadThreads(y);
  // the level's step unless one is given here: a strong soil whose adhesion ramp the level's step
  // cannot follow runs at the step the guard names, the rest of the level unchanged
  if (y.Has("time_step")) p.level.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  p.seed = static_cast<unsigned>(y.Int("seed", 1));
  p.sample_interval = y.DoubleIn("sample_interval", 1e-4, 1.0, 0.01);
  const YamlReader c = y.Child("container");
  p.container_segments = c.Int("segments", 24);
  if (p.container_segments < 8 || p.container_segments > 512) c.Fail("segments", "must lie in [8, 512]");
  p.solid_fraction = c.DoubleIn("solid_fraction", 0.2, 0.74, 0.58);
  c.Finish();
  const YamlReader k = y.Child("cone");
  p.base_diameter = k.Positive("base_diameter");
  p.cone_length = k.Positive("length");
  p.cone_angle_deg = k.DoubleIn("angle_deg", 1.0, 179.0);
  p.rod_diameter = k.Positive("rod_diameter");
  p.cone_mass = k.Positive("mass");
  p.cone_friction = k.DoubleIn("friction", 0.0, 5.0);
  p.start_gap = k.NonNegative("start_gap", 0.02);
  p.cone_segments = k.Int("segments", 24);
  if (p.cone_segments < 6 || p.cone_segments > 512) k.Fail("segments", "must lie in [6, 512]");
  const double length = 0.5 * p.base_diameter / std::tan(0.5 * p.cone_angle_deg * M_PI / 180.0);
  if (std::abs(length - p.cone_length) > 0.01 * p.cone_length)
    k.Fail("length", "a " + detail::Concat(p.cone_angle_deg) + "-degree cone of base diameter " +
                         detail::Concat(p.base_diameter) + " m is " + detail::Concat(length) + " m long, not " +
                         detail::Concat(p.cone_length) + " m");
  if (p.rod_diameter >= p.base_diameter) k.Fail("rod_diameter", "must be smaller than the base diameter");
  k.Finish();
  const YamlReader pid = y.Child("pid");
  p.kp = pid.Positive("kp");
  p.ki = pid.NonNegative("ki");
  p.kd = pid.NonNegative("kd");
  pid.Finish();
  const YamlReader lid = y.Child("lid");
  p.lid_pressure = lid.Positive("pressure");
  p.lid_speed = lid.DoubleIn("speed", 1e-4, 10.0);
  p.release_time = lid.DoubleIn("release_time", 0.0, 100.0);
  lid.Finish();
  y.Finish();
  const ConeLevel& l = p.level;
  const std::string where = "levels." + l.name;
  if (p.base_diameter + 2.0 * l.particle_diameter > l.container_diameter)
    y.Fail("cone.base_diameter", "the cone (" + detail::Concat(p.base_diameter) +
                                     " m) is wider than the container of level '" + l.name + "' (" +
                                     detail::Concat(l.container_diameter) + " m, less two particle diameters)");
  // the surface ends up near 0.7 of the poured depth (less for a weak soil); the window must end
  // above the floor
  if (l.ci_to + 2.0 * l.particle_diameter > 0.7 * l.soil_depth)
    y.Fail(where + ".ci_window", "ends at a tip depth of " + detail::Concat(l.ci_to) + " m, too deep for soil poured " +
                                     detail::Concat(l.soil_depth) + " m deep (it settles to about " +
                                     detail::Concat(0.7 * l.soil_depth) + " m)");
  if (l.approach_speed > 0.0 && !(l.approach_depth < l.ci_from))
    y.Fail(where + ".approach_depth", "must end above the CI window (" + detail::Concat(l.ci_from) +
                                         " m): the window is penetrated at cone_speed");
  if (l.ci_from < p.cone_length)
    y.Fail(where + ".ci_window", "starts at a tip depth of " + detail::Concat(l.ci_from) +
                                     " m, before the cone's base (" + detail::Concat(p.cone_length) +
                                     " m) is in the soil: the force is then not a steady state");
  return p;
}

int ConeParams::ParticleCount() const {
  const double r = 0.5 * level.container_diameter, d = level.particle_diameter;
  return static_cast<int>(std::lround(solid_fraction * M_PI * r * r * level.soil_depth / (M_PI / 6.0 * d * d * d)));
}

double ConeParams::BaseArea() const { return M_PI * 0.25 * base_diameter * base_diameter; }

std::string ConePenetrometer::phase() const {
  switch (phase_) {
    case Phase::kPrepare: return SoilPreparation::PhaseName(prep_->phase());
    case Phase::kPenetrate: return "penetrate";
    case Phase::kDone: return "done";
  }
  return "?";
}

std::string ConePenetrometer::StatusLine() const {
  char buf[160];
  if (penetrating()) {
    const double ci = samples_.empty() ? 0.0 : samples_.back().cone_index_psi;
    std::snprintf(buf, sizeof buf, "t %.2f s  %s  tip depth %.3f / %.3f m  CI %.1f psi", dem_->time(),
                  phase().c_str(), tip_depth(), p_.level.ci_to, ci);
  } else {
    std::snprintf(buf, sizeof buf, "t %.2f s  %s", dem_->time(), phase().c_str());
  }
  return buf;
}

ConePenetrometer::ConePenetrometer(const ConeParams& p) : p_(p), wall0_(std::chrono::steady_clock::now()) {
  const double R = 0.5 * p.level.container_diameter;
  DemSettings st;
  st.threads = p.threads;
  // near a cone at CI 240 psi (1.7 MPa) a pair overlaps by d0 (5 %), twice the plastic deformation
  // (up to 8 %) and the elastic strain of the local stress peaks: allow that, not a blow-up
  st.max_overlap = 0.4;
  dem_ = std::make_unique<DemSystem>(p.soil, st);
  DemSystem& s = *dem_;
  const CylinderBed bed = AddCylinderBed(&s, R, p.ParticleCount(), p.container_segments, p.seed);
  floor_ = bed.floor;
  lid_ = bed.lid;
  const double park_z = bed.wall_height + 1.0;
  const double rod_length = p.level.ci_to + 0.5;
  DemWall cone = MakeConeWall("cone", 0.5 * p.base_diameter, p.cone_length, p.cone_segments);
  cone.friction = p.cone_friction;
  z_tip_ = park_z + 1.0;
  cone.position = Vector3d(0, 0, z_tip_);
  cone.wrench_point = cone.position;
  cone_ = s.AddWall(std::move(cone));
  DemWall rod = MakeRodWall("rod", 0.5 * p.rod_diameter, rod_length, p.cone_segments);
  rod.friction = p.cone_friction;
  rod.position = Vector3d(0, 0, z_tip_ + p.cone_length);
  rod_ = s.AddWall(std::move(rod));
  s.Finalize(p.level.time_step);
  SoilPreparationParams prep;
  prep.settle_time = p.level.settle_time;
  prep.lid_pressure = p.lid_pressure;
  prep.lid_speed = p.lid_speed;
  prep.hold_time = p.level.hold_time;
  prep.release_time = p.release_time;
  prep.timeout = 30.0;
  prep_ = std::make_unique<SoilPreparation>(&s, lid_, M_PI * R * R, park_z, prep, "cone penetrometer");
}

ConePenetrometer::~ConePenetrometer() = default;

double ConePenetrometer::penetration_force() const {
  return dem_->wall(cone_).force.z() + dem_->wall(rod_).force.z();
}

void ConePenetrometer::Reference(double t, double* z, double* v) const {
  const ConeLevel& l = p_.level;
  const double s = t - t0_;
  // at approach_speed from the start down to approach_depth, then at cone_speed
  const double d1 = l.approach_speed > 0.0 ? (z0_ - surface_) + l.approach_depth : 0.0;
  const double t1 = l.approach_speed > 0.0 ? d1 / l.approach_speed : 0.0;
  if (s < t1) {
    *z = z0_ - l.approach_speed * s;
    *v = -l.approach_speed;
  } else {
    *z = z0_ - d1 - l.cone_speed * (s - t1);
    *v = -l.cone_speed;
  }
}

void ConePenetrometer::PlaceCone() {
  // above the consolidated surface, or above a particle standing higher over the cone's base (one
  // the lid lifted with it): the cone's walls jump to their start, and a particle they land in
  // would trip the overlap watchdog
  const double r = 0.5 * p_.base_diameter + 0.5 * p_.level.particle_diameter;
  double top = surface_;
  dem_->ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
    if (x.x() * x.x() + x.y() * x.y() < r * r) top = std::max(top, x.z() + 0.5 * p_.level.particle_diameter);
  });
  z_tip_ = z0_ = top + p_.start_gap;
  v_tip_ = p_.level.approach_speed > 0.0 ? -p_.level.approach_speed : -p_.level.cone_speed;
  t0_ = dem_->time();
  // the integral starts at the weight, so the cone does not sag when it is let go
  integral_ = p_.ki > 0.0 ? p_.cone_mass * 9.81 / p_.ki : 0.0;
  sample_z_ = z_tip_;
  sample_t_ = t0_;
}

void ConePenetrometer::StepCone() {
  // PID on the prescribed tip height, the soil's force from the last evaluation, semi-implicit Euler
  const double dt = p_.level.time_step, t = dem_->time() + dt;
  double z_ref = 0.0, v_ref = 0.0;
  Reference(t, &z_ref, &v_ref);
  const double e = z_ref - z_tip_, de = v_ref - v_tip_;
  integral_ += e * dt;
  const double actuator = p_.kp * e + p_.ki * integral_ + p_.kd * de;
  const double accel = (actuator + penetration_force()) / p_.cone_mass - 9.81;
  v_tip_ += accel * dt;
  z_tip_ += v_tip_ * dt;
  DemWall& cone = dem_->mutable_wall(cone_);
  cone.position = Vector3d(0, 0, z_tip_);
  cone.velocity = Vector3d(0, 0, v_tip_);
  cone.wrench_point = cone.position;
  DemWall& rod = dem_->mutable_wall(rod_);
  rod.position = Vector3d(0, 0, z_tip_ + p_.cone_length);
  rod.velocity = cone.velocity;
  rod.wrench_point = cone.position;
}

void ConePenetrometer::Step() {
  switch (phase_) {
    case Phase::kPrepare:
      prep_->Step();
      if (prep_->done()) StartPenetration();
      break;
    case Phase::kPenetrate:
      StepCone();
      dem_->Step();
      Sample();
      break;
    case Phase::kDone: break;
  }
}

void ConePenetrometer::StartPenetration() {
  const double d = p_.level.particle_diameter;
  surface_ = prep_->height_consolidated();
  if (surface_ - p_.level.ci_to < 2.0 * d)
    throw SimulationError("cone penetrometer: the soil settled to " + detail::Concat(surface_) +
                          " m, too shallow for the CI window's end at a tip depth of " + detail::Concat(p_.level.ci_to) +
                          " m (pour more: levels." + p_.level.name + ".soil_depth)");
  PlaceCone();
  StepCone();  // cone walls to their start (a jump: the next step rebuilds the lists)
  z_tip_ = z0_;
  v_tip_ = p_.level.approach_speed > 0.0 ? -p_.level.approach_speed : -p_.level.cone_speed;
  phase_ = Phase::kPenetrate;
}

void ConePenetrometer::Sample() {
  const DemSystem& s = *dem_;
  sample_force_ += penetration_force();
  ++sample_steps_;
  if (s.time() - sample_t_ < p_.sample_interval - 0.5 * p_.level.time_step) return;
  ConeSample c;
  c.t = s.time() - t0_;
  c.depth = tip_depth();
  c.speed = (sample_z_ - z_tip_) / (s.time() - sample_t_);
  c.force = sample_force_ / sample_steps_;
  c.cone_index_psi = c.force / p_.BaseArea() / kPsi;
  samples_.push_back(c);
  sample_force_ = 0.0;
  sample_steps_ = 0;
  sample_z_ = z_tip_;
  sample_t_ = s.time();
  if (c.depth >= p_.level.ci_to) phase_ = Phase::kDone;
}

ConeResult ConePenetrometer::Run(const std::function<void(const ConePenetrometer&)>& progress, long every) {
  RunSoilRig(*this, progress ? [&](const SoilRig&) { progress(*this); } : std::function<void(const SoilRig&)>(),
             every);
  return Result();
}

ConeResult ConePenetrometer::Result() const {
  ConeResult r;
  const double d = p_.level.particle_diameter, R = 0.5 * p_.level.container_diameter;
  r.level = p_.level.name;
  r.particles = dem_->num_alive();
  r.cohesion_factor = p_.strength.cohesion_factor;
  r.friction = p_.friction;
  r.requested_cone_index_psi = p_.strength.requested_cone_index_psi;
  r.surface_height = surface_;
  const double mass = r.particles * dem_->mass(), area = M_PI * R * R;
  if (prep_->height_poured() > 0.0) r.density_poured = mass / (area * prep_->height_poured());
  if (prep_->height_consolidated() > 0.0) r.density_consolidated = mass / (area * prep_->height_consolidated());
  r.lid_pressure_reached = prep_->lid_pressure_reached();
  r.rest = prep_->rest();
  r.samples = samples_;
  // the cone index: the samples in the window, their scatter and their trend with depth
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  r.speed_min = 1e30;
  r.speed_max = -1e30;
  // the speed once the tip is in the soil (and past the approach, if any)
  const double speed_from = std::max(d, p_.level.approach_speed > 0.0 ? p_.level.approach_depth + d : 0.0);
  for (const ConeSample& c : samples_) {
    if (c.depth >= speed_from) {
      r.speed_min = std::min(r.speed_min, c.speed);
      r.speed_max = std::max(r.speed_max, c.speed);
    }
    if (c.depth < p_.level.ci_from || c.depth > p_.level.ci_to + 1e-9) continue;
    n += 1;
    sx += c.depth;
    sy += c.cone_index_psi;
    sxx += c.depth * c.depth;
    sxy += c.depth * c.cone_index_psi;
    syy += c.cone_index_psi * c.cone_index_psi;
  }
  if (r.speed_min > r.speed_max) r.speed_min = r.speed_max = 0.0;
  r.window_samples = static_cast<int>(n);
  if (n > 0) {
    r.cone_index_psi = sy / n;
    r.cone_index_std_psi = std::sqrt(std::max(0.0, syy / n - r.cone_index_psi * r.cone_index_psi));
    const double vx = sxx / n - (sx / n) * (sx / n);
    if (n > 1 && vx > 0.0) r.cone_index_trend_psi_per_m = (sxy / n - (sx / n) * (sy / n)) / vx;
  }
  r.prep_time = penetrating() ? t0_ : dem_->time();
  r.sim_time = dem_->time();
  r.time_step = p_.level.time_step;
  r.steps = dem_->step_count();
  r.wall_time = WallTime();
  r.error = error_;
  if (r.error.empty() && phase_ != Phase::kDone) r.error = "interrupted in phase " + phase();
  return r;
}

ResultFile ConeResultFile(const ConeResult& r, const ConeParams& p) {
  ResultFile f(p.file, "cone_penetrometer");
  f.SetStatus(r.error.empty() ? "ok" : (r.error.rfind("interrupted", 0) == 0 ? "interrupted" : "error"), r.error);
  f.Set("fidelity", r.level);
  f.Set("cohesion_factor", r.cohesion_factor);
  f.Set("friction", r.friction);
  if (std::isfinite(r.requested_cone_index_psi)) f.Set("requested_cone_index_psi", r.requested_cone_index_psi);
  if (p.strength.calibration) p.strength.calibration->Describe(&f);  // which table f came from, and its error
  f.Set("cone_index_psi", r.cone_index_psi);
  f.Set("cone_index_std_psi", r.cone_index_std_psi);
  f.Set("cone_index_trend_psi_per_m", r.cone_index_trend_psi_per_m);
  f.SetFlow("ci_window", {p.level.ci_from, p.level.ci_to});
  f.Set("window_samples", r.window_samples);
  f.Set("cone_speed_min", r.speed_min);
  f.Set("cone_speed_max", r.speed_max);
  f.Set("particles", r.particles);
  f.Set("particle_diameter", p.level.particle_diameter);
  f.Set("container_diameter", p.level.container_diameter);
  f.Set("soil_depth", p.level.soil_depth);
  f.Set("cone_speed", p.level.cone_speed);
  if (p.level.approach_speed > 0.0) {
    f.Set("approach_speed", p.level.approach_speed);
    f.Set("approach_depth", p.level.approach_depth);
  }
  f.Set("seed", p.seed);
  f.Set("surface_height", r.surface_height);
  f.Set("bulk_density_poured", r.density_poured);
  f.Set("bulk_density_consolidated", r.density_consolidated);
  f.Set("lid_pressure_reached", r.lid_pressure_reached);
  DescribeRest(r.rest, "settle_", &f);
  f.Set("time_step", r.time_step);
  f.Set("steps", r.steps);
  f.Set("preparation_time", r.prep_time);
  f.Set("simulated_time", r.sim_time);
  f.Set("wall_time", r.wall_time);
  f.Set("threads", p.threads);
  // the CI history (fig. 13): one column per quantity
  std::vector<double> t, depth, speed, force, ci;
  for (const ConeSample& c : r.samples) {
    t.push_back(c.t);
    depth.push_back(c.depth);
    speed.push_back(c.speed);
    force.push_back(c.force);
    ci.push_back(c.cone_index_psi);
  }
  f.SetColumns("history", {{"t", t}, {"tip_depth", depth}, {"speed", speed}, {"force", force}, {"cone_index_psi", ci}});
  return f;
}

ResultFile ConePenetrometer::Report() const { return ConeResultFile(Result(), p_); }

double ConePenetrometer::WallTime() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
}

template <class Ar>
void ConePenetrometer::Io(Ar& ar) {
  ar.Tag("cone_penetrometer");
  dem_->Io(ar);
  prep_->Io(ar);
  ar.Tag("cone");
  double wall = WallTime();  // (the run's wall time so far goes on counting after a restart)
  ar(phase_, z_tip_, v_tip_, integral_, z0_, t0_, surface_, sample_force_, sample_z_, sample_t_, sample_steps_,
     samples_, wall);
  if constexpr (Ar::kLoading) {
    if (static_cast<int>(phase_) < 0 || phase_ > Phase::kDone) ar.Fail("the cone's phase is not one");
    wall0_ = WallClockStartFor(wall);
  }
}

void ConePenetrometer::SaveState(StateWriter& out) const { const_cast<ConePenetrometer*>(this)->Io(out); }
void ConePenetrometer::LoadState(StateReader& in) { Io(in); }

}  // namespace dem_mobility::core
