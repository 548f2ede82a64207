#include "dem_mobility/core/terrain/dem_soil.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/terrain/prepared_soil_cache.h"
#include "dem_mobility/core/terrain/soil_patch.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {
/// What a dem_soil terrain of these parameters says it is.
TerrainDescription SoilDescription(const DemSoilParams& p) {
  TerrainDescription d;
  d.file = p.file;
  d.model = "dem_soil";
  d.cone_index = p.strength.ConeIndex();
  d.time_step = p.level.time_step;
  d.fidelity = p.level.name;
  return d;
}
}  // namespace

DemSoilTerrain::DemSoilTerrain(const DemSoilParams& p, const TireGeometry& tire, int wheels,
                               const PreparationHooks& hooks)
    : bin_(std::make_unique<DemSoilBin>(p, tire, wheels)) {
  const auto t0 = std::chrono::steady_clock::now();
  auto wall = [&t0] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  description_ = SoilDescription(p);
  // progress when a phase begins, every progress_every wall seconds within one, and at the end
  // (the phase compared as its enum and the clock read only with a listener: nothing per step else)
  bool told = false;
  SoilPreparation::Phase told_phase{};
  double told_at = 0.0;
  auto tell = [&] {
    if (!hooks.progress) return;
    const SoilPreparation::Phase phase = bin_->preparation().phase();
    const double w = wall();
    if (told && phase == told_phase && w - told_at < hooks.progress_every) return;
    told = true;
    told_phase = phase;
    told_at = w;
    hooks.progress(PreparationProgress{SoilPreparation::PhaseName(phase), bin_->dem().time(), w,
                                       bin_->dem().num_alive(), bin_->preparation().Detail()});
  };
  while (!bin_->prepared()) {
    if (hooks.stop && hooks.stop())
      throw Interrupted(detail::Concat("interrupted while the soil (", p.file, ", level ", p.level.name, ", ",
                                       bin_->dem().num_alive(), " particles) was being prepared: phase ", bin_->phase(),
                                       ", ", bin_->dem().time(), " s of the preparation simulated in ", wall(), " s"));
    tell();
    bin_->PrepareStep();
  }
  tell();
  // The vehicle starts with its tires touching the plane z = 0. That plane goes through the top of
  // the highest particle of the bed's interior (a diameter and more from the walls), so that no
  // tire starts inside a particle; the bed's surface (the mean top of its highest particles, from
  // which sinkage is measured) is then start_gap_ below it, and the vehicle settles onto the soil.
  {
    const double d = p.level.particle_diameter, margin = 1.5 * d;
    const double x0 = p.origin.x() + margin, x1 = p.origin.x() + p.level.length - margin;
    const double y_max = 0.5 * p.level.width - margin;
    double top = -std::numeric_limits<double>::infinity();
    bin_->dem().ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
      if (x.x() > x0 && x.x() < x1 && std::abs(x.y() - p.origin.y()) < y_max) top = std::max(top, x.z() + 0.5 * d);
    });
    start_gap_ = std::isfinite(top) ? std::max(0.0, top - bin_->surface_height()) : 0.0;
  }
  bin_->ShiftZ(-bin_->surface_height() - start_gap_);
  if (p.patch.enabled) patch_ = std::make_unique<SoilPatch>(bin_.get(), p.patch, p.seed);
  MakeSurfaceMesh();
  wrenches_.assign(wheels, WheelWrench());
  bin_->WatchEnergy(0.05);  // the run's energy ledger from here (20 samples per second of soil time)
  prepare_wall_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void DemSoilTerrain::MakeSurfaceMesh() {
  const DemSoilParams& p = bin_->params();
  const SoilBinLevel& l = p.level;
  const double z = bin_->surface_height();
  const Vector3d o = p.origin - Vector3d(0.0, 0.5 * l.width, 0.0);
  const double length = l.length + (p.patch.enabled ? p.patch.travel : 0.0);
  surface_mesh_.vertices = {Vector3d(o.x(), o.y(), z), Vector3d(o.x() + length, o.y(), z),
                            Vector3d(o.x() + length, o.y() + l.width, z), Vector3d(o.x(), o.y() + l.width, z)};
  surface_mesh_.faces = {{0, 1, 2}, {0, 2, 3}};
}

DemSoilTerrain::DemSoilTerrain(const DemSoilTerrain& o)
    : TerrainModel(),
      bin_(std::make_unique<DemSoilBin>(*o.bin_)),
      patch_(o.patch_ ? std::make_unique<SoilPatch>(*o.patch_, bin_.get()) : nullptr),
      prepare_wall_(o.prepare_wall_),
      advance_wall_(o.advance_wall_),
      start_gap_(o.start_gap_),
      description_(o.description_),
      surface_mesh_(o.surface_mesh_),
      states_(o.states_),
      wrenches_(o.wrenches_) {}

DemSoilTerrain::~DemSoilTerrain() = default;

TerrainDisplay DemSoilTerrain::Display() const {
  TerrainDisplay d;
  d.dem = &bin_->dem();
  if (!patch_) return d;
  d.walls = {bin_->leveling_cylinder(), bin_->leveling_plate()};
  d.patch = true;
  d.sphere_centre = patch_->sphere_centre();
  d.sphere_radius = patch_->sphere_radius();
  d.box_rear = patch_->box_rear();
  d.box_front = patch_->box_front();
  d.box_width = bin_->params().level.width;
  d.floor_z = bin_->floor_z();
  d.box_height = bin_->wall_height();
  d.emitter_from = patch_->emitter_from();
  d.emitter_to = patch_->emitter_to();
  const DemSoilParams& p = bin_->params();
  if (p.strip_width > 0.0) {
    for (const auto& b : p.SoilBands()) d.strips.emplace_back(p.origin.y() + b.first, p.origin.y() + b.second);
    d.strip_floor_z = bin_->floor_z() + std::max(0.5 * p.level.particle_diameter, p.level.soil_depth - 1.5 * p.level.particle_diameter);
  }
  return d;
}

void DemSoilTerrain::SetGravity(const Vector3d& g) {
  DM_THROW_UNLESS(g.allFinite() && g.norm() > 0.0, "dem_soil terrain: gravity ", g.transpose(), " is not a direction");
  bin_->dem().set_gravity(g);
  // the run's ledger from the grade on (turning gravity is not energy the run passes through)
  bin_->WatchEnergy(0.05);
}

void DemSoilTerrain::Describe(ResultFile* r) const {
  const DemSoilParams& p = bin_->params();
  p.Describe(r);
  if (std::isfinite(p.level.speed_error))
    r->Set("speed_error_estimate", p.level.speed_error);
  else
    r->Set("speed_error_estimate", std::string("not measured for level '") + p.level.name + "'");
  if (!p.level.speed_error_note.empty()) r->Set("speed_error_note", p.level.speed_error_note);
  r->Set("soil_time_step", p.level.time_step);
  // the grade the soil's own weight is on (its gravity against the bed's normal, -z)
  const Vector3d g = bin_->dem().gravity();
  r->Set("soil_grade_deg", std::atan2(-g.x(), -g.z()) * 180.0 / M_PI);
  r->Set("particles", bin_->dem().num_alive());
  r->Set("soil_depth", bin_->surface_height() - bin_->floor_z());
  r->Set("soil_start_gap", start_gap_);
  r->Set("soil_prepare_wall_time", prepare_wall_);
  if (!prepared_from_.empty()) r->Set("soil_prepared_from", prepared_from_);
  r->Set("soil_advance_wall_time", advance_wall_);
  r->Set("soil_steps", bin_->dem().step_count());
  r->Set("soil_neighbour_builds", bin_->dem().neighbour_builds());
  r->Set("soil_wall_builds", bin_->dem().wall_builds());
  bin_->DescribeEnergy(r);
  if (!patch_) return;
  const PatchStats& s = patch_->stats();
  r->Set("patch_following", s.following);
  // 0: soil over the box's width; else the strips' width (soil only under the wheel tracks)
  r->Set("patch_track_strip_width", p.strip_width);
  r->Set("patch_travel", patch_->sphere_centre().x() - bin_->params().origin.x() - 0.5 * p.level.length);
  r->Set("patch_reemitted", s.reemitted);
  r->Set("patch_strays", s.strays);
  r->Set("patch_template_copies", s.copies);
  r->Set("patch_skipped_sites", s.skipped_sites);
  // (a figure not measured yet, such as the checks of a run too short for the patch to lay soil
  // ahead, is null)
  r->SetMeasured("patch_face_setback", s.face_setback);
  r->Set("patch_initial_density", s.initial.density);
  r->Set("patch_initial_surface", s.initial.surface);
  r->Set("patch_checks", s.checks);
  r->SetMeasured("patch_density_ratio", s.density_ratio_mean);
  r->SetMeasured("patch_density_ratio_min", s.density_ratio_min);
  r->SetMeasured("patch_density_ratio_max", s.density_ratio_max);
  r->SetMeasured("patch_surface_offset", s.surface_offset_mean);
  r->SetMeasured("patch_surface_offset_max", s.surface_offset_max);
  r->Set("patch_bed_slide_speed_max", s.bed_slide_speed_max);
}

void DemSoilTerrain::Synchronize(long, double, const std::vector<WheelState>& states) {
  DM_THROW_UNLESS(static_cast<int>(states.size()) == bin_->wheels(), "dem_soil: ", states.size(),
                  " wheel states for ", bin_->wheels(), " tires");
  states_ = states;
}

void DemSoilTerrain::GetWrenches(std::vector<WheelWrench>* wrenches) const { *wrenches = wrenches_; }

void DemSoilTerrain::Advance(double dt) {
  if (dt == 0.0) return;
  const double h = bin_->params().level.time_step;
  const double ratio = dt / h;
  const long n = std::lround(ratio);
  if (n < 1 || std::abs(ratio - n) > 1e-6 * ratio)
    throw SimulationError(detail::Concat("dem_soil (", bin_->params().file, "): the exchange step ", dt,
                                         " s is not a whole multiple of the soil's time step ", h,
                                         " s (levels.", bin_->params().level.name, ".time_step)"));
  const auto t0 = std::chrono::steady_clock::now();
  const int W = bin_->wheels();
  std::vector<WheelWrench> sum(W);
  std::vector<Vector3d> centres(W);
  for (long k = 1; k <= n; ++k) {
    // each tire moves on at its synchronized velocities to where it is at the end of this step
    for (int w = 0; w < W; ++w) {
      WheelState s = states_[w];
      const double t = k * h;
      s.position += s.velocity * t;
      const double angle = s.angular_velocity.norm() * t;
      if (angle > 0.0)
        s.orientation = Eigen::AngleAxisd(angle, s.angular_velocity.normalized()) * s.orientation;
      bin_->SetWheel(w, s);
      centres[w] = s.position;
    }
    if (patch_) patch_->BeforeStep(centres);
    bin_->Step();
    for (int w = 0; w < W; ++w) {
      const WheelWrench r = bin_->Wrench(w);
      sum[w].force += r.force;
      sum[w].moment += r.moment + (bin_->dem().wall(bin_->tire_wall(w)).position - states_[w].position).cross(r.force);
      sum[w].normal_force += r.normal_force;
      if (k == n) {
        sum[w].contacts = r.contacts;
        sum[w].sinkage = r.sinkage;
        sum[w].stiffness = r.stiffness;
        sum[w].damping = r.damping;
      }
    }
  }
  for (int w = 0; w < W; ++w) {
    sum[w].force /= n;
    sum[w].moment /= n;
    sum[w].normal_force /= n;
  }
  wrenches_ = sum;
  advance_wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {
/// The bin's parameters read from `y` and checked against `vehicle` (the strips on its track).
DemSoilParams ReadDemSoilFor(const YamlReader& y, const TerrainVehicle& vehicle) {
  const DemSoilParams p = DemSoilParams::Read(y);
  y.String("model");
  y.Finish();
  DemSoilParams q = p;
  const SoilBinLevel& l = p.level;
  if (p.strip_width > 0.0) {
    if (vehicle.wheels < 2 || !(vehicle.track > 0.0))
      throw ConfigError(detail::Concat(p.file, ": track_strip_width: soil under the wheel tracks needs a vehicle with a track (this one has ",
                                       vehicle.wheels, " wheels, track ", vehicle.track, " m)"));
    q.strip_offset = 0.5 * vehicle.track;
  }
  const double needed = vehicle.track + vehicle.tire.width + 2.0 * l.particle_diameter;
  if (vehicle.wheels > 1 && vehicle.track > 0.0 && needed > l.width)
    throw ConfigError(detail::Concat(p.file, ": levels.", l.name, ".width: the soil (", l.width,
                                     " m wide) is narrower than the vehicle's track (", vehicle.track,
                                     " m) plus a tire width and two particle diameters (", needed, " m)"));
  if (p.patch.enabled && vehicle.wheelbase > 0.0) {
    // The emitter lays ahead only what leaves the sphere's rear half, and the sphere (holding the
    // whole box) reaches past the box's rear by its radius less half the box's length: the soil
    // laid ahead trails the sphere's front by that much. When the patch starts to follow, the
    // front wheels stand half the wheelbase ahead of the box's middle, so the laid soil stands
    // ahead of them by half the box less that lag and half the wheelbase. The patch's checks look
    // at the window check_window ahead of the front wheels, the soil they meet: it must be laid.
    const double d = l.particle_diameter, half_w = 0.5 * l.width, mid = 0.5 * l.soil_depth + d;
    const auto ahead = [&](double length) {
      const double radius = std::sqrt(0.25 * length * length + half_w * half_w + mid * mid) + p.patch.sphere_margin;
      return 0.5 * length - (radius - 0.5 * length) - 0.5 * vehicle.wheelbase;
    };
    if (ahead(l.length) < p.patch.check_to) {
      double shortest = l.length;
      while (ahead(shortest) < p.patch.check_to) shortest += 0.1;
      throw ConfigError(detail::Concat(p.file, ": levels.", l.name, ".length: a box ", l.length, " m long lays its soil only ",
                                       ahead(l.length), " m ahead of the front wheels (wheelbase ", vehicle.wheelbase,
                                       " m), short of the end of patch.check_window (", p.patch.check_to,
                                       " m): the wheels would meet soil not yet laid; at least ", shortest, " m"));
    }
  }
  return q;
}
}  // namespace

std::unique_ptr<TerrainModel> MakeDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle,
                                                 const PreparationHooks& hooks) {
  InputFileRecord inputs;
  const DemSoilParams p = ReadDemSoilFor(y, vehicle);
  if (hooks.described) hooks.described(SoilDescription(p));
  if (hooks.prepared_soil_cache.empty()) return std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, hooks);
  const std::string path = PreparedSoilCache(hooks.prepared_soil_cache).PathOf(y, inputs.Files(), vehicle);
  std::unique_ptr<DemSoilTerrain> t;
  const auto t0 = std::chrono::steady_clock::now();
  if (PreparedSoilCache::Read(path, [&](StateReader& r) { t = std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, r); })) {
    t->SetPreparedFrom(path, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return t;
  }
  t = std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, hooks);
  PreparedSoilCache::Keep(path, [&t](StateWriter& w) { t->SaveState(w); });
  return t;
}

void CheckDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle) { ReadDemSoilFor(y, vehicle); }

TerrainDescription DescribeDemSoilTerrain(const YamlReader& y) {
  return SoilDescription(DemSoilParams::Read(y));
}

template <class Ar>
void DemSoilTerrain::Io(Ar& ar) {
  ar.Tag("dem_soil_terrain");
  {
    // what soil it is (a checkpoint of another soil stops here, naming both)
    const DemSoilParams& p = bin_->params();
    const std::string what = detail::Concat("level ", p.level.name, ", d ", p.level.particle_diameter, " m, bin ",
                                            p.level.length, " x ", p.level.width, " m, f ", p.strength.cohesion_factor, ", mu ",
                                            p.friction, ", strips ", p.strip_width, " m, patch ", p.patch.enabled,
                                            ", seed ", p.seed);
    ar.Tag(what.c_str());
  }
  bin_->Io(ar);
  ar(prepare_wall_, advance_wall_, start_gap_, states_, wrenches_);
  unsigned char has_patch = patch_ ? 1 : 0;
  ar(has_patch);
  if constexpr (Ar::kLoading) {
    const DemSoilParams& p = bin_->params();
    if (has_patch != (p.patch.enabled ? 1 : 0))
      ar.Fail(std::string("the checkpoint's soil ") + (has_patch ? "has" : "has no") + " moving patch, the scene's " +
              (p.patch.enabled ? "has one" : "has none"));
    if (!bin_->prepared()) ar.Fail("the soil in it is not prepared");
    if (wrenches_.size() != static_cast<size_t>(bin_->wheels()) ||
        (!states_.empty() && states_.size() != static_cast<size_t>(bin_->wheels())))
      ar.Fail("the wheels' states do not match the tires");
    if (has_patch && !patch_) {
      // (read, not measured: the restoring constructor reads every figure of the patch)
      patch_ = std::make_unique<SoilPatch>(bin_.get(), p.patch, ar);
      return;
    }
  }
  if (patch_) patch_->Io(ar);
}

DemSoilTerrain::DemSoilTerrain(const DemSoilParams& p, const TireGeometry& tire, int wheels, StateReader& in)
    : bin_(std::make_unique<DemSoilBin>(p, tire, wheels)) {
  description_ = SoilDescription(p);
  wrenches_.assign(wheels, WheelWrench());
  Io(in);
  MakeSurfaceMesh();
}

void DemSoilTerrain::SaveState(StateWriter& out) const { const_cast<DemSoilTerrain*>(this)->Io(out); }
void DemSoilTerrain::LoadState(StateReader& in) { Io(in); }

std::unique_ptr<TerrainModel> RestoreDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle, StateReader& in) {
  return std::make_unique<DemSoilTerrain>(ReadDemSoilFor(y, vehicle), vehicle.tire, vehicle.wheels, in);
}

}  // namespace dem_mobility::core
