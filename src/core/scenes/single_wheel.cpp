#include "dem_mobility/core/scenes/single_wheel.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

const char* SingleWheelParams::DriveName(Drive d) {
  switch (d) {
    case Drive::kSlip: return "slip";
    case Drive::kTowed: return "towed";
    case Drive::kTorque: return "torque";
  }
  return "?";
}

std::pair<std::string, std::string> SingleWheelParams::DriveProblem(Drive drive, double slip, double torque) {
  if (!(slip >= -1.0 && slip <= 1.0)) return {"slip", "must lie in [-1, 1], not " + detail::Concat(slip)};
  if (drive == Drive::kSlip && slip == 1.0)
    return {"slip", "of 1 needs an infinite wheel speed at a moving carriage: use a slip below 1"};
  if (!(torque >= -1e5 && torque <= 1e5)) return {"torque", "must lie in [-1e5, 1e5] N m, not " + detail::Concat(torque)};
  return {};
}

SingleWheelParams SingleWheelParams::Read(const YamlReader& y) {
  SingleWheelParams p;
  p.file = y.file();
  const std::string scene = y.String("scene");
  if (scene != "single_wheel") y.Fail("scene", "expected 'single_wheel', found '" + scene + "'");
  p.bin = DemSoilParams::Read(y);
  p.tire_file = y.ResolvePath(y.String("tire"));
  p.tire = TireGeometry::Read(YamlReader::Load(p.tire_file));
  const YamlReader w = y.Child("wheel");
  const std::string drive = w.String("drive");
  if (drive == "slip") {
    p.drive = Drive::kSlip;
  } else if (drive == "towed") {
    p.drive = Drive::kTowed;
  } else if (drive == "torque") {
    p.drive = Drive::kTorque;
  } else {
    w.Fail("drive", "must be slip, towed or torque, not '" + drive + "'");
  }
  p.slip = w.Double("slip", 0.2);
  p.torque = w.Double("torque", 0.0);
  const auto [key, problem] = DriveProblem(p.drive, p.slip, p.torque);
  if (!key.empty()) w.Fail(key, problem);
  p.load_mass = w.DoubleIn("load_mass", 1.0, 1e5);
  p.speed = w.DoubleIn("speed", 1e-3, 20.0);
  p.wheel_inertia = w.DoubleIn("inertia", 1e-3, 1e4, 6.0);
  w.Finish();
  const YamlReader c = y.Child("carriage");
  p.carriage_damping = c.DoubleIn("damping", 0.0, 1e8);
  p.load_time = c.DoubleIn("load_time", 0.0, 100.0);
  p.settle_time = c.DoubleIn("settle_time", 0.0, 100.0);
  p.accel_time = c.DoubleIn("accel_time", 0.0, 100.0);
  p.start_x = c.NonNegative("start_x");
  const std::vector<double> win = c.DoubleList("window");
  if (win.size() != 2 || !(win[0] >= 0.0 && win[1] > win[0]))
    c.Fail("window", "must be [from, to] carriage travel with 0 <= from < to");
  p.window_from = win[0];
  p.window_to = win[1];
  p.sunk_sinkage = c.DoubleIn("sunk_sinkage", 0.05, 1.0, 0.5);
  c.Finish();
  p.sample_interval = y.DoubleIn("sample_interval", 1e-4, 1.0, 0.01);
  y.Finish();
  // the wheel must fit in the bin, start clear of its end wall and stop before the other
  const SoilBinLevel& l = p.bin.level;
  const double R = p.tire.radius, d = l.particle_diameter;
  const std::string where = "levels." + l.name;
  if (p.tire.width + 2.0 * d > l.width)
    y.Fail(where + ".width", "the bin (" + detail::Concat(l.width) + " m) is narrower than the tire (" +
                                 detail::Concat(p.tire.width) + " m) plus two particle diameters");
  if (p.start_x < R + 2.0 * d)
    y.Fail("carriage.start_x", "puts the tire into the bin's end wall: it must be at least the radius plus two "
                               "particle diameters (" + detail::Concat(R + 2.0 * d) + " m)");
  if (p.start_x + p.window_to + R + 2.0 * d > l.length)
    y.Fail("carriage.window", "ends at x = " + detail::Concat(p.start_x + p.window_to) + " m: the tire would reach the end of the " +
                                  detail::Concat(l.length) + " m bin of level '" + l.name + "'");
  return p;
}

// ---------------------------------------------------------------------------------------------

SingleWheelRig::SingleWheelRig(const SingleWheelParams& p) : p_(p), wall0_(std::chrono::steady_clock::now()) {
  bin_ = std::make_unique<DemSoilBin>(p.bin, p.tire, 1);
}

SingleWheelRig::SingleWheelRig(const SingleWheelParams& p, const DemSoilBin& prepared)
    : p_(p), wall0_(std::chrono::steady_clock::now()) {
  const DemSoilParams& a = p.bin;
  const DemSoilParams& b = prepared.params();
  if (a.level.name != b.level.name || a.strength.cohesion_factor != b.strength.cohesion_factor || a.friction != b.friction ||
      a.seed != b.seed || a.soil.file != b.soil.file || prepared.wheels() != 1 ||
      prepared.tire().soil_mesh.faces.size() != p.tire.soil_mesh.faces.size() || prepared.tire().radius != p.tire.radius)
    throw ConfigError(p.file + ": the prepared bin was made for another soil, level, seed or tire");
  bin_ = std::make_unique<DemSoilBin>(prepared);
  if (bin_->prepared()) {
    Place();
    bin_->WatchEnergy(0.05);  // as Step() does once the rig's own preparation ends
    phase_ = Phase::kLoad;
  }
}

SingleWheelRig::SingleWheelRig(const SingleWheelRig& o)
    : p_(o.p_),
      bin_(std::make_unique<DemSoilBin>(*o.bin_)),
      phase_(o.phase_),
      wheel_(o.wheel_),
      x0_(o.x0_), x_(o.x_), z_(o.z_), vz_(o.vz_), v_(o.v_), omega_(o.omega_), theta_(o.theta_),
      t_phase_(o.t_phase_), dp_(o.dp_), torque_(o.torque_), accel_(o.accel_),
      sunk_(o.sunk_),
      s_dp_(o.s_dp_), s_torque_(o.s_torque_), s_fz_(o.s_fz_), s_sink_(o.s_sink_), s_omega_(o.s_omega_),
      s_t0_(o.s_t0_), s_x0_(o.s_x0_), s_n_(o.s_n_),
      rest_fz_(o.rest_fz_), rest_sink_(o.rest_sink_), rest_n_(o.rest_n_),
      samples_(o.samples_),
      wall0_(o.wall0_),
      prep_wall_time_(o.prep_wall_time_),
      error_(o.error_) {}

SingleWheelRig::SingleWheelRig(const SingleWheelRig& rested, SingleWheelParams::Drive drive, double slip,
                               double torque)
    : SingleWheelRig(rested) {
  if (phase_ != Phase::kDrive || t_phase_ != 0.0)
    throw ConfigError(p_.file + ": a rig takes another drive only after its rest and before its first drive step (it is in '" +
                      phase() + "')");
  const auto [key, problem] = SingleWheelParams::DriveProblem(drive, slip, torque);  // (Read's bounds)
  if (!key.empty()) throw ConfigError(p_.file + ": wheel." + key + ": " + problem);
  p_.drive = drive;
  p_.slip = slip;
  p_.torque = torque;
}

std::string SingleWheelRig::phase() const {
  switch (phase_) {
    case Phase::kPrepare: return bin_->phase();
    case Phase::kLoad: return "load";
    case Phase::kSettle: return "settle";
    case Phase::kDrive: return "drive";
    case Phase::kDone: return sunk_ ? "sunk" : "done";
  }
  return "?";
}

double SingleWheelRig::wall_time() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
}

template <class Ar>
void SingleWheelRig::Io(Ar& ar) {
  ar.Tag("single_wheel");
  bin_->Io(ar);
  ar.Tag("wheel");
  wheel_.Io(ar);
  double wall = wall_time();  // (the run's wall time so far goes on counting after a restart)
  ar(phase_, x0_, x_, z_, vz_, v_, omega_, theta_, t_phase_, dp_, torque_, accel_, sunk_, s_dp_, s_torque_, s_fz_,
     s_sink_, s_omega_, s_t0_, s_x0_, s_n_, rest_fz_, rest_sink_, rest_n_, samples_, prep_wall_time_, wall);
  if constexpr (Ar::kLoading) {
    if (static_cast<int>(phase_) < 0 || phase_ > Phase::kDone) ar.Fail("the wheel rig's phase is not one");
    wall0_ = WallClockStartFor(wall);
  }
}

void SingleWheelRig::SaveState(StateWriter& out) const { const_cast<SingleWheelRig*>(this)->Io(out); }
void SingleWheelRig::LoadState(StateReader& in) { Io(in); }

double SingleWheelRig::sinkage() const { return bin_->surface_height() - (z_ - p_.tire.radius); }

std::string SingleWheelRig::StatusLine() const {
  char buf[200];
  if (phase_ == Phase::kPrepare) {
    std::snprintf(buf, sizeof buf, "t %.2f s  %s", dem().time(), phase().c_str());
  } else {
    const double W = p_.Weight();
    std::snprintf(buf, sizeof buf, "t %.2f s  %s  travel %.2f / %.2f m  sinkage %.3f m  DP/W %.3f  T/(Wr) %.3f",
                  dem().time(), phase().c_str(), travel(), p_.window_to, sinkage(), dp_ / W,
                  torque_ / (W * p_.tire.radius));
  }
  return buf;
}

void SingleWheelRig::Place() {
  const double d = p_.bin.level.particle_diameter;
  x0_ = x_ = p_.bin.origin.x() + p_.start_x;
  z_ = bin_->surface_height() + p_.tire.radius + 0.25 * d;  // just above the surface
  vz_ = v_ = omega_ = theta_ = 0.0;
  t_phase_ = 0.0;
  prep_wall_time_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
}

void SingleWheelRig::StepWheel() {
  // the carriage and the wheel over one DEM step: the soil's wrench from the last evaluation,
  // semi-implicit Euler; the tire goes where the step ends
  const double h = p_.bin.level.time_step, m = p_.load_mass, W = p_.Weight(), R = p_.tire.radius;
  const WheelWrench f = bin_->Wrench(0);
  t_phase_ += h;
  const double load = phase_ == Phase::kLoad && p_.load_time > 0.0 ? std::min(1.0, t_phase_ / p_.load_time) : 1.0;
  vz_ += h * (f.force.z() - load * W - p_.carriage_damping * vz_) / m;
  z_ += h * vz_;
  if (phase_ == Phase::kDrive) {
    const double v = p_.speed * (p_.accel_time > 0.0 ? std::min(1.0, t_phase_ / p_.accel_time) : 1.0);
    accel_ = (v - v_) / h;
    v_ = v;
    x_ += h * v_;
    const double omega_old = omega_;
    const double my = f.moment.y();  // the soil's moment about the axle (forward rolling: +y)
    switch (p_.drive) {
      case SingleWheelParams::Drive::kSlip:
        omega_ = v_ / (R * (1.0 - p_.slip));
        torque_ = p_.wheel_inertia * (omega_ - omega_old) / h - my;
        break;
      case SingleWheelParams::Drive::kTowed:
        torque_ = 0.0;
        omega_ += h * my / p_.wheel_inertia;
        break;
      case SingleWheelParams::Drive::kTorque:
        torque_ = p_.torque;
        omega_ += h * (p_.torque + my) / p_.wheel_inertia;
        break;
    }
    dp_ = f.force.x() - m * accel_;
  } else {
    dp_ = f.force.x();
    torque_ = -f.moment.y();  // what holds the wheel still
  }
  theta_ += h * omega_;
  wheel_.position = Vector3d(x_, p_.bin.origin.y(), z_);
  wheel_.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(theta_, Vector3d::UnitY()));
  wheel_.velocity = Vector3d(v_, 0.0, vz_);
  wheel_.angular_velocity = Vector3d(0.0, omega_, 0.0);
  bin_->SetWheel(0, wheel_);
}

void SingleWheelRig::Step() {
  const double R = p_.tire.radius, d = p_.bin.level.particle_diameter;
  switch (phase_) {
    case Phase::kPrepare:
      bin_->PrepareStep();
      if (bin_->prepared()) {
        Place();
        bin_->WatchEnergy(0.05);  // the soil's energy ledger over the rig's run
        phase_ = Phase::kLoad;
      }
      return;
    case Phase::kLoad:
    case Phase::kSettle:
    case Phase::kDrive:
      StepWheel();
      bin_->Step();
      break;
    case Phase::kDone: return;
  }
  // a load the soil cannot carry: the wheel sinks to the floor or past the sunk depth
  if (sinkage() > p_.sunk_sinkage * R || z_ - R < p_.bin.origin.z() + 2.0 * d) {
    sunk_ = true;
    phase_ = Phase::kDone;
    return;
  }
  if (phase_ == Phase::kSettle && t_phase_ >= 0.5 * p_.settle_time) {
    rest_fz_ += bin_->Wrench(0).force.z();
    rest_sink_ += sinkage();
    ++rest_n_;
  }
  if (phase_ == Phase::kLoad && t_phase_ >= p_.load_time - 0.5 * p_.bin.level.time_step) {
    phase_ = Phase::kSettle;
    t_phase_ = 0.0;
  } else if (phase_ == Phase::kSettle && t_phase_ >= p_.settle_time - 0.5 * p_.bin.level.time_step) {
    phase_ = Phase::kDrive;
    t_phase_ = 0.0;
    s_t0_ = dem().time();
    s_x0_ = x_;
  } else if (phase_ == Phase::kDrive) {
    Sample();
    if (travel() >= p_.window_to) phase_ = Phase::kDone;
  }
}

void SingleWheelRig::Sample() {
  const WheelWrench f = bin_->Wrench(0);
  s_dp_ += dp_;
  s_torque_ += torque_;
  s_fz_ += f.force.z();
  s_sink_ += sinkage();
  s_omega_ += omega_;
  ++s_n_;
  const double dt = dem().time() - s_t0_;
  if (dt < p_.sample_interval - 0.5 * p_.bin.level.time_step) return;
  WheelSample s;
  const double n = static_cast<double>(s_n_);
  s.t = t_phase_;
  s.travel = travel();
  s.speed = (x_ - s_x0_) / dt;
  s.omega = s_omega_ / n;
  s.slip = s.omega > 0.0 ? 1.0 - s.speed / (s.omega * p_.tire.radius) : 0.0;
  s.sinkage = s_sink_ / n;
  s.drawbar_pull = s_dp_ / n;
  s.torque = s_torque_ / n;
  s.vertical_force = s_fz_ / n;
  s.contacts = f.contacts;
  samples_.push_back(s);
  s_dp_ = s_torque_ = s_fz_ = s_sink_ = s_omega_ = 0.0;
  s_n_ = 0;
  s_t0_ = dem().time();
  s_x0_ = x_;
}

SingleWheelRig::Window SingleWheelRig::Measured() const {
  Window w;
  double dp2 = 0, t2 = 0, z2 = 0;
  for (const WheelSample& s : samples_) {
    if (s.travel < p_.window_from || s.travel > p_.window_to + 1e-9) continue;
    ++w.samples;
    w.dp += s.drawbar_pull;
    dp2 += s.drawbar_pull * s.drawbar_pull;
    w.torque += s.torque;
    t2 += s.torque * s.torque;
    w.sinkage += s.sinkage;
    z2 += s.sinkage * s.sinkage;
    w.slip += s.slip;
    w.omega += s.omega;
    w.vertical_force += s.vertical_force;
  }
  if (w.samples == 0) return w;
  const double n = w.samples;
  w.dp /= n;
  w.torque /= n;
  w.sinkage /= n;
  w.slip /= n;
  w.omega /= n;
  w.vertical_force /= n;
  w.dp_std = std::sqrt(std::max(0.0, dp2 / n - w.dp * w.dp));
  w.torque_std = std::sqrt(std::max(0.0, t2 / n - w.torque * w.torque));
  w.sinkage_std = std::sqrt(std::max(0.0, z2 / n - w.sinkage * w.sinkage));
  return w;
}

ResultFile SingleWheelRig::Report() const { return SingleWheelResultFile(*this); }

ResultFile SingleWheelResultFile(const SingleWheelRig& rig) {
  const SingleWheelParams& p = rig.params();
  const DemSoilBin& bin = rig.bin();
  const DemSystem& s = bin.dem();
  ResultFile f(p.file, "single_wheel");
  const SingleWheelRig::Window w = rig.Measured();
  std::string error;
  std::string status = "ok";
  if (!rig.error().empty()) {
    status = "error";
    error = rig.error();
  } else if (!rig.done()) {
    status = "interrupted";
    error = "interrupted in phase " + rig.phase();
  } else if (rig.sunk()) {
    status = "sunk";
    error = detail::Concat("the wheel sank ", rig.sinkage(), " m (", rig.sinkage() / p.tire.radius,
                           " of its radius) in phase '", rig.driving() ? "drive" : "load",
                           "': the soil does not carry ", p.load_mass, " kg");
  }
  f.SetStatus(status, error);
  p.bin.Describe(&f);
  bin.DescribeEnergy(&f);
  f.Set("drive", std::string(SingleWheelParams::DriveName(p.drive)));
  if (p.drive == SingleWheelParams::Drive::kSlip) f.Set("slip_commanded", p.slip);
  if (p.drive == SingleWheelParams::Drive::kTorque) f.Set("torque_commanded", p.torque);
  f.Set("load_mass", p.load_mass);
  f.Set("load", p.Weight());
  f.Set("carriage_speed", p.speed);
  f.Set("tire", p.tire_file);
  f.Set("tire_radius", p.tire.radius);
  f.Set("tire_width", p.tire.width);
  f.Set("tire_triangles", static_cast<long>(p.tire.soil_mesh.faces.size()));
  f.SetFlow("window", {p.window_from, p.window_to});
  f.Set("window_samples", w.samples);
  const double W = p.Weight(), R = p.tire.radius;
  f.Set("drawbar_pull", w.dp);
  f.Set("drawbar_pull_std", w.dp_std);
  f.Set("dp_over_w", w.dp / W);
  f.Set("dp_over_w_std", w.dp_std / W);
  f.Set("torque", w.torque);
  f.Set("torque_std", w.torque_std);
  f.Set("torque_over_wr", w.torque / (W * R));
  f.Set("torque_over_wr_std", w.torque_std / (W * R));
  f.Set("sinkage", w.sinkage);
  f.Set("sinkage_std", w.sinkage_std);
  f.Set("slip", w.slip);
  f.Set("wheel_speed", w.omega);
  f.Set("vertical_force", w.vertical_force);
  f.Set("rest_vertical_force", rig.rest_vertical_force());
  f.Set("rest_load_ratio", rig.rest_vertical_force() / W);
  f.Set("rest_sinkage", rig.rest_sinkage());
  f.Set("particles", s.num_alive());
  f.Set("surface_height", bin.surface_height());
  const SoilBinLevel& l = p.bin.level;
  const double area = l.length * l.width;
  const double mass = s.num_alive() * s.mass();
  if (bin.preparation().height_consolidated() > 0.0)
    f.Set("bulk_density_consolidated", mass / (area * (bin.preparation().height_consolidated() - p.bin.origin.z())));
  f.Set("lid_pressure_reached", bin.preparation().lid_pressure_reached());
  DescribeRest(bin.preparation().rest(), "settle_", &f);
  f.SetFlow("bin", {l.length, l.width, l.soil_depth});
  f.Set("time_step", l.time_step);
  f.Set("steps", s.step_count());
  f.Set("simulated_time", s.time());
  f.Set("wall_builds", s.wall_builds());
  f.Set("neighbour_builds", s.neighbour_builds());
  f.Set("threads", p.bin.threads);
  f.Set("preparation_wall_time", rig.preparation_wall_time());
  f.Set("wall_time", rig.wall_time());
  std::vector<double> t, travel, speed, omega, slip, sink, dp, tq, fz, dpw, twr;
  for (const WheelSample& x : rig.samples()) {
    t.push_back(x.t);
    travel.push_back(x.travel);
    speed.push_back(x.speed);
    omega.push_back(x.omega);
    slip.push_back(x.slip);
    sink.push_back(x.sinkage);
    dp.push_back(x.drawbar_pull);
    tq.push_back(x.torque);
    fz.push_back(x.vertical_force);
    dpw.push_back(x.drawbar_pull / W);
    twr.push_back(x.torque / (W * R));
  }
  f.SetColumns("history", {{"t", t}, {"travel", travel}, {"speed", speed}, {"omega", omega}, {"slip", slip},
                           {"sinkage", sink}, {"drawbar_pull", dp}, {"torque", tq}, {"vertical_force", fz},
                           {"dp_over_w", dpw}, {"torque_over_wr", twr}});
  return f;
}

}  // namespace dem_mobility::core
