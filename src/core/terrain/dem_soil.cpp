#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/common/input_files.h"
#include "dem_mobility/core/common/state_archive.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"
#include "dem_mobility/core/terrain/soil_patch.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

constexpr double kMinCohesionFactor = 0.05, kMaxCohesionFactor = 12.0;  // the paper's range

SoilBinLevel ReadBinLevel(const YamlReader& y, const std::string& name) {
  SoilBinLevel l;
  l.name = name;
  l.particle_diameter = y.DoubleIn("particle_diameter", 0.005, 0.5);
  l.length = y.DoubleIn("length", 0.1, 1000.0);
  l.width = y.DoubleIn("width", 0.1, 100.0);
  l.soil_depth = y.DoubleIn("soil_depth", 0.05, 10.0);
  l.time_step = y.DoubleIn("time_step", 1e-8, 1e-3);
  l.settle_time = y.DoubleIn("settle_time", 0.0, 100.0);
  l.hold_time = y.DoubleIn("hold_time", 0.0, 100.0);
  if (y.Has("speed_error")) l.speed_error = y.DoubleIn("speed_error", 0.0, 100.0);
  if (y.Has("speed_error_note")) l.speed_error_note = y.String("speed_error_note");
  y.Finish();
  if (l.soil_depth < 3.0 * l.particle_diameter)
    y.Fail("soil_depth", "must be at least three particle diameters (" + detail::Concat(3.0 * l.particle_diameter) + " m)");
  return l;
}

}  // namespace

DemSoilParams DemSoilParams::Read(const YamlReader& y) {
  DemSoilParams p;
  p.file = y.file();
  p.soil = SoilParams::Read(YamlReader::Load(y.ResolvePath(y.String("soil"))));
  p.level = ReadFidelityLevel<SoilBinLevel>(y, ReadBinLevel);  // every level checked, the named one used
  p.friction = y.DoubleIn("friction", 0.0, 2.0);
  // the soil: f directly, or from a requested cone index through the calibration table made at
  // this level's particle size
  if (y.Has("calibration")) p.calibration_file = y.ResolvePath(y.String("calibration"));
  const bool by_ci = SoilStrengthByConeIndex(y);  // (the one an override gives, where both are there)
  if (by_ci) {
    p.requested_ci = y.Positive("cone_index");
    if (p.calibration_file.empty()) y.Fail("calibration", "is needed to turn cone_index into f");
    try {
      p.calibration = std::make_shared<CiCalibration>(
          CiCalibration::LoadFor(p.calibration_file, p.level.particle_diameter, p.friction));
      p.cohesion_factor = p.calibration->CohesionFactor(p.requested_ci);
    } catch (const ConfigError& e) {
      y.Fail("cone_index", e.what());
    }
  } else {
    if (!y.Has("cohesion_factor")) y.Fail("cohesion_factor", "is not set (nor is cone_index)");
    p.cohesion_factor = y.Double("cohesion_factor");
    if (!p.calibration_file.empty()) {
      // a table at this particle size only names the CI this f stands for; without one the CI
      // is unknown (and the result says why)
      try {
        p.calibration = std::make_shared<CiCalibration>(
            CiCalibration::LoadFor(p.calibration_file, p.level.particle_diameter, p.friction));
      } catch (const ConfigError& e) {
        p.no_table_reason = e.what();
      }
    }
  }
  if (!(p.cohesion_factor >= kMinCohesionFactor && p.cohesion_factor <= kMaxCohesionFactor))
    y.Fail(by_ci ? "cone_index" : "cohesion_factor",
           "the cohesion factor f = " + detail::Concat(p.cohesion_factor) + " lies outside the paper's range [" +
               detail::Concat(kMinCohesionFactor) + ", " + detail::Concat(kMaxCohesionFactor) + "]");
  p.soil.diameter = p.level.particle_diameter;
  p.soil.cohesion_factor = p.cohesion_factor;
  p.soil.friction = p.friction;
  p.threads = ReadThreads(y);
  p.seed = static_cast<unsigned>(y.Int("seed", 1));
  p.time_step_guard = y.Bool("time_step_guard", true);
  if (y.Has("bin")) {
    const YamlReader b = y.Child("bin");
    p.origin = b.Vector3("origin", Vector3d::Zero());
    p.solid_fraction = b.DoubleIn("solid_fraction", 0.2, 0.74, 0.58);
    p.consolidation = b.DoubleIn("consolidation", 0.3, 1.0, 0.7);
    p.max_overlap = b.DoubleIn("max_overlap", 0.05, 0.9, 0.4);
    b.Finish();
  }
  const YamlReader lid = y.Child("lid");
  p.prep.lid_pressure = lid.Positive("pressure");
  p.prep.lid_speed = lid.DoubleIn("speed", 1e-4, 10.0);
  p.prep.release_time = lid.DoubleIn("release_time", 0.0, 100.0);
  p.prep.timeout = lid.DoubleIn("timeout", 0.1, 1000.0, 30.0);
  lid.Finish();
  p.prep.settle_time = p.level.settle_time;
  p.prep.hold_time = p.level.hold_time;
  if (y.Has("tire_contact")) {
    const YamlReader t = y.Child("tire_contact");
    p.tire_friction = t.DoubleIn("friction", 0.0, 5.0, 0.5);
    p.tire_adhesion = t.DoubleIn("adhesion_factor", 0.0, 10.0, 0.0);
    p.wall_margin = t.DoubleIn("margin", 0.0, 1.0, 0.0);
    t.Finish();
  }
  if (y.Has("track_strip_width")) {
    p.strip_width = y.DoubleIn("track_strip_width", 0.0, 100.0);
    if (p.strip_width > 0.0 && !y.Has("patch"))
      y.Fail("track_strip_width", "soil only under the wheel tracks is an option of the vehicle's moving patch (no patch: here)");
  }
  if (y.Has("patch")) {
    p.patch = SoilPatchParams::Read(y.Child("patch"));
    const double h = p.patch.leveling_ahead + p.patch.leveling_radius;
    if (h > 0.5 * p.level.length)
      y.Fail("patch.leveling.ahead", detail::Concat("the leveling cylinder (", h, " m ahead of the front wheels) must lie within half the bin's length (",
                                                    0.5 * p.level.length, " m)"));
  }
  return p;
}

std::vector<std::pair<double, double>> DemSoilParams::SoilBands() const {
  if (strip_width <= 0.0) return {{-0.5 * level.width, 0.5 * level.width}};
  const double h = 0.5 * strip_width;
  return {{-strip_offset - h, -strip_offset + h}, {strip_offset - h, strip_offset + h}};
}

double DemSoilParams::SoilWidth() const { return strip_width > 0.0 ? 2.0 * strip_width : level.width; }

int DemSoilParams::ParticleCount() const {
  const double d = level.particle_diameter;
  const double poured = level.soil_depth / consolidation;
  return static_cast<int>(std::lround(solid_fraction * level.length * SoilWidth() * poured / (M_PI / 6.0 * d * d * d)));
}

double DemSoilParams::ConeIndex() const {
  if (std::isfinite(requested_ci)) return requested_ci;
  if (!calibration) return std::numeric_limits<double>::quiet_NaN();
  try {
    return calibration->ConeIndex(cohesion_factor);
  } catch (const ConfigError&) {
    return std::numeric_limits<double>::quiet_NaN();  // f outside the table: no CI to name
  }
}

void DemSoilParams::Describe(ResultFile* r) const {
  r->Set("fidelity", level.name);
  if (!time_step_guard) r->Set("soil_time_step_guard", false);
  r->Set("particle_diameter", level.particle_diameter);
  r->Set("cohesion_factor", cohesion_factor);
  r->Set("friction", friction);
  if (std::isfinite(requested_ci)) r->Set("requested_cone_index_psi", requested_ci);
  const double ci = ConeIndex();
  if (std::isfinite(ci))
    r->Set("cone_index_psi", ci);
  else
    r->Set("cone_index_psi", std::string("unknown: f given directly and no calibration table names its CI") +
                                 (no_table_reason.empty() ? std::string() : " (" + no_table_reason + ")"));
  if (calibration) calibration->Describe(r);
}

namespace {
/// What a dem_soil terrain of these parameters says it is.
TerrainDescription SoilDescription(const DemSoilParams& p) {
  TerrainDescription d;
  d.file = p.file;
  d.model = "dem_soil";
  d.cone_index = p.ConeIndex();
  d.time_step = p.level.time_step;
  d.fidelity = p.level.name;
  return d;
}
}  // namespace

// ---------------------------------------------------------------------------------------------

DemSoilBin::DemSoilBin(const DemSoilParams& p, const TireGeometry& tire, int wheels) : p_(p), tire_(tire) {
  const SoilBinLevel& l = p.level;
  const double d = l.particle_diameter;
  DM_THROW_UNLESS(wheels >= 1 && wheels <= 64, "dem_soil: ", wheels, " wheels (1 to 64)");
  if (tire.width + 2.0 * d > l.width)
    throw ConfigError(detail::Concat(p.file, ": levels.", l.name, ".width: the bin (", l.width,
                                     " m) is narrower than the tire (", tire.width, " m) plus two particle diameters"));
  DemSettings st;
  st.threads = p.threads;
  st.max_overlap = p.max_overlap;
  st.check_time_step = p.time_step_guard;
  // a moving patch re-emits a layer at a time next to the soil's front: room for the new pairs
  if (p.patch.enabled) st.list_slack = 6;
  dem_ = std::make_unique<DemSystem>(p.soil, st);
  DemSystem& s = *dem_;
  const Vector3d o = p.origin - Vector3d(0.0, 0.5 * l.width, 0.0);
  // the soil's bands across y (the whole width, or a strip under each wheel track), in the bin's
  // frame (y from its side wall y0)
  std::vector<std::pair<double, double>> bands = p.SoilBands();
  for (auto& b : bands) {
    b.first += 0.5 * l.width;
    b.second += 0.5 * l.width;
  }
  if (p.strip_width > 0.0) {
    if (!(p.strip_offset > 0.0))
      throw ConfigError(p.file + ": track_strip_width: soil under the wheel tracks needs the vehicle's track (none given)");
    if (tire.width + 2.0 * d > p.strip_width)
      throw ConfigError(detail::Concat(p.file, ": track_strip_width: the strips (", p.strip_width, " m) are narrower than the tire (",
                                       tire.width, " m) plus two particle diameters"));
    if (bands[0].first < 0.0 || bands[1].second > l.width || bands[1].first - bands[0].second < 2.0 * d)
      throw ConfigError(detail::Concat(p.file, ": track_strip_width: two strips ", p.strip_width, " m wide centred ",
                                       p.strip_offset, " m either side of the centre line (half the vehicle's track) must lie within the bin (levels.",
                                       l.name, ".width ", l.width, " m) and leave two particle diameters (", 2.0 * d,
                                       " m) between them"));
  }
  std::vector<Vector3d> lattice;
  if (bands.size() == 1) {
    lattice = PourLattice(
        p.ParticleCount(), d, 1.1, {0.0, 0.0}, {l.length, l.width},
        [&](double x, double y) { return x >= 0.6 * d && x <= l.length - 0.6 * d && y >= 0.6 * d && y <= l.width - 0.6 * d; },
        p.seed, /*spread_last_layer=*/p.patch.enabled);  // a vehicle's patch: level across its width
  } else {
    // each strip poured between its own walls, its lattice centred between them, half the soil
    const int count = p.ParticleCount();
    for (size_t k = 0; k < bands.size(); ++k) {
      const double y0 = bands[k].first, y1 = bands[k].second;
      const int n = k == 0 ? count / 2 : count - count / 2;
      const std::vector<Vector3d> strip = PourLattice(
          n, d, 1.1, {0.0, y0}, {l.length, y1},
          [&](double x, double y) { return x >= 0.6 * d && x <= l.length - 0.6 * d && y >= y0 + 0.6 * d && y <= y1 - 0.6 * d; },
          p.seed + 7919u * static_cast<unsigned>(k), /*spread_last_layer=*/true);
      lattice.insert(lattice.end(), strip.begin(), strip.end());
    }
  }
  double top = 0.0;
  for (const Vector3d& x : lattice) top = std::max(top, x.z());
  wall_height_ = top + 2.0 * d;
  // a moving patch's floor and sides reach over the whole travel (their material stays put)
  const double reach = p.patch.enabled ? l.length + p.patch.travel : l.length;
  std::vector<DemWall> box = MakeOpenBoxWalls(reach, l.width, wall_height_);
  box[2] = MakeQuadWall("x1", {l.length, 0, 0}, {0, l.width, 0}, {0, 0, wall_height_});
  if (bands.size() > 1) {
    // each strip between walls of its own (from the floor to the box's height), and a rigid floor
    // over the rest of the width, between the strips and beside them: 1.5 d below the bed's
    // nominal surface (soil spilled onto it passes under the leveling plate), and kept half a
    // diameter from the strips' walls (a particle inside a strip never reaches its edge: pressed by
    // the wall and by the floor's edge, a particle there would be pushed twice)
    std::vector<double> edges = {0.0};
    for (const auto& b : bands) {
      // (none where a strip's side is the box's: two walls there would press the soil twice)
      if (b.first > 1e-9) box.push_back(MakeQuadWall("strip_side", {0, b.first, 0}, {reach, 0, 0}, {0, 0, wall_height_}));
      if (b.second < l.width - 1e-9)
        box.push_back(MakeQuadWall("strip_side", {0, b.second, 0}, {reach, 0, 0}, {0, 0, wall_height_}));
      edges.push_back(b.first);
      edges.push_back(b.second);
    }
    edges.push_back(l.width);
    const double z_gap = std::max(0.5 * d, l.soil_depth - 1.5 * d);
    for (size_t k = 0; k + 1 < edges.size(); k += 2) {
      const double y0 = edges[k] > 1e-9 ? edges[k] + 0.5 * d : 0.0;
      const double y1 = edges[k + 1] < l.width - 1e-9 ? edges[k + 1] - 0.5 * d : l.width;
      if (y1 - y0 > 1e-9) box.push_back(MakeQuadWall("track_gap_floor", {0, y0, z_gap}, {reach, 0, 0}, {0, y1 - y0, 0}));
    }
  }
  for (DemWall& w : box) {
    for (Vector3d& v : w.mesh.vertices) v += o;
    container_.push_back(s.AddWall(std::move(w)));
  }
  DemWall lid = MakeQuadWall("lid", Vector3d(0, 0, 0), Vector3d(l.length, 0, 0), Vector3d(0, l.width, 0));
  for (Vector3d& v : lid.mesh.vertices) v += Vector3d(o.x(), o.y(), 0.0);
  lid.position = Vector3d(0, 0, o.z() + top + d);
  lid_ = s.AddWall(std::move(lid));
  // the tires: parked high above the bin until a wheel state puts them somewhere
  for (int k = 0; k < wheels; ++k) {
    DemWall w;
    w.name = wheels == 1 ? std::string("tire") : std::string("tire_") + (k < kWheels ? kWheelNames[k] : std::to_string(k));
    w.mesh = tire.soil_mesh;
    w.friction = p.tire_friction;
    w.adhesion_factor = p.tire_adhesion;
    w.fast = true;
    w.margin = p.wall_margin;
    w.position = o + Vector3d(0.5 * l.length + 3.0 * k, 0.5 * l.width, wall_height_ + 10.0 + tire.radius);
    w.wrench_point = w.position;
    centres_.push_back(w.position);
    tire_walls_.push_back(s.AddWall(std::move(w)));
  }
  if (p.patch.enabled) {
    // the leveling cylinder (axis along y) and plate, parked above until the patch starts
    const double span = l.width - d;
    DemWall c = MakeRodWall("leveling_cylinder", p.patch.leveling_radius, span, 16);
    for (Vector3d& v : c.mesh.vertices) v = Vector3d(v.x(), -v.z() + 0.5 * span, v.y());
    c.fast = true;
    c.friction = p.tire_friction;
    c.position = o + Vector3d(0.5 * l.length, 0.5 * l.width, wall_height_ + 20.0);
    cylinder_ = s.AddWall(std::move(c));
    DemWall pl = MakeQuadWall("leveling_plate", Vector3d(0, -0.5 * span, 0), Vector3d(p.patch.plate_length, 0, 0),
                              Vector3d(0, span, 0));
    pl.fast = true;
    pl.friction = p.tire_friction;
    pl.position = o + Vector3d(0.5 * l.length, 0.5 * l.width, wall_height_ + 25.0);
    plate_ = s.AddWall(std::move(pl));
  }
  for (const Vector3d& x : lattice) s.AddParticle(o + x);
  s.Finalize(l.time_step);
  prep_ = std::make_unique<SoilPreparation>(&s, lid_, l.length * p.SoilWidth(), o.z() + wall_height_ + 1.0, p.prep,
                                            "dem_soil bin (" + p.file + ")");
}

DemSoilBin::DemSoilBin(const DemSoilBin& o)
    : p_(o.p_),
      tire_(o.tire_),
      dem_(std::make_unique<DemSystem>(*o.dem_)),
      prep_(std::make_unique<SoilPreparation>(*o.prep_, dem_.get())),
      tire_walls_(o.tire_walls_),
      container_(o.container_),
      centres_(o.centres_),
      lid_(o.lid_),
      cylinder_(o.cylinder_),
      plate_(o.plate_),
      wall_height_(o.wall_height_),
      surface_(o.surface_),
      shift_(o.shift_),
      watch_(o.watch_),
      watch_every_(o.watch_every_),
      watch_start_(o.watch_start_),
      watch_plastic_(o.watch_plastic_) {}

void DemSoilBin::WatchEnergy(double period) {
  watch_ = LedgerWatch();
  watch_every_ = std::max(1L, std::lround(period / dem_->dt()));
  dem_->set_plastic_ledger(true);  // the law's own plastic exchange in the ledger: `dissipated` is the dampers' and friction's
  watch_plastic_ = dem_->plastic_exchange();
  // the least scale: the soil's weight times a particle diameter
  watch_.floor = dem_->num_alive() * dem_->mass() * dem_->gravity().norm() * p_.level.particle_diameter;
  watch_start_ = dem_->Energy();
  watch_.Sample(watch_start_, dem_->time());
}

void DemSoilBin::DescribeEnergy(ResultFile* r) const {
  const TimeStepLimit lim = dem_->CriticalTimeStep();
  r->Set("soil_critical_time_step", lim.dt_crit);
  r->Set("soil_critical_detail", lim.detail);
  if (watch_.samples == 0) return;
  const EnergyReport e = dem_->Energy();
  r->Set("soil_energy_wall_work", e.wall_work - watch_start_.wall_work);
  r->Set("soil_energy_exchanged", e.exchanged - watch_start_.exchanged);
  r->Set("soil_energy_plastic", dem_->plastic_exchange() - watch_plastic_);
  r->SetLedger("soil_energy", watch_);
}

void DemSoilBin::ShiftZ(double dz) {
  DemSystem& s = *dem_;
  std::vector<int> ids;
  s.ForEachParticle([&](int id, const Vector3d&, const Vector3d&) { ids.push_back(id); });
  for (int id : ids) s.mutable_position(id).z() += dz;
  for (int w = 0; w < s.num_walls(); ++w) {
    s.mutable_wall(w).position.z() += dz;
    s.mutable_wall(w).wrench_point.z() += dz;
  }
  for (Vector3d& c : centres_) c.z() += dz;
  surface_ += dz;
  shift_ += dz;
}

void DemSoilBin::PrepareStep() {
  prep_->Step();
  if (prep_->done()) surface_ = prep_->height_consolidated();  // (the particles are in the scene frame)
}

void DemSoilBin::SetWheel(int k, const WheelState& s) {
  DM_THROW_UNLESS(s.position.allFinite() && s.velocity.allFinite() && s.angular_velocity.allFinite() &&
                      s.orientation.coeffs().allFinite(),
                  "dem_soil: wheel ", k, " state is not finite");
  DemWall& w = dem_->mutable_wall(tire_walls_[k]);
  w.position = s.position;
  w.rotation = s.orientation.normalized().toRotationMatrix();
  w.velocity = s.velocity;
  w.angular_velocity = s.angular_velocity;
  w.wrench_point = s.position;
  centres_[k] = s.position;
}

WheelWrench DemSoilBin::Wrench(int k) const {
  const DemWall& w = dem_->wall(tire_walls_[k]);
  WheelWrench r;
  r.force = w.force;
  r.moment = w.moment;
  r.contacts = w.contacts;
  r.normal_force = w.normal_force;
  r.sinkage = w.contacts > 0 ? std::max(0.0, surface_ - (centres_[k].z() - tire_.radius)) : 0.0;
  // each contact is one particle's spring and dashpot (eq. 12b): their sum bounds the tire's
  r.stiffness = w.contacts * p_.soil.NormalStiffness();
  r.damping = w.contacts * p_.soil.NormalDamping();
  return r;
}

// ---------------------------------------------------------------------------------------------

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

namespace {
// a prepared soil in DM_SOIL_CACHE: this line, the format, DemSoilTerrain's state (SealState)
const std::string kSoilMagic = "dem_mobility prepared soil\n";
constexpr uint32_t kSoilFormat = 2;  // 2: the DEM state without its scratch (the plastic pass's, the pair kernels' hot records)

/// The cache file of a soil: named by the fingerprint of everything its preparation depends on
/// (the terrain file with its overrides, the files its reading read, the tire, this build).
std::string PreparedSoilPath(const std::string& dir, const YamlReader& y, const std::vector<InputFile>& files,
                             const TerrainVehicle& vehicle) {
  std::string key = y.Dump();
  for (const InputFile& f : files) key += "\n" + f.path + " " + std::to_string(f.fingerprint);
  const TriMesh& m = vehicle.tire.soil_mesh;
  key += detail::Concat("\ntire ", vehicle.tire.radius, " ", vehicle.tire.width, " wheels ", vehicle.wheels,
                        " track ", vehicle.track, " wheelbase ", vehicle.wheelbase, " build ", ExecutableFingerprint(),
                        " format ", kSoilFormat);
  uint64_t h = Fnv1a(key.data(), key.size());
  if (!m.vertices.empty()) h = Fnv1a(m.vertices.data(), m.vertices.size() * sizeof(m.vertices[0]), h);
  if (!m.faces.empty()) h = Fnv1a(m.faces.data(), m.faces.size() * sizeof(m.faces[0]), h);
  char name[64];
  std::snprintf(name, sizeof name, "soil_%016llx.prepared", static_cast<unsigned long long>(h));
  return (std::filesystem::path(dir) / name).string();
}
}  // namespace

std::unique_ptr<TerrainModel> MakeDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle,
                                                 const PreparationHooks& hooks) {
  InputFileRecord inputs;
  const DemSoilParams p = ReadDemSoilFor(y, vehicle);
  const char* dir = std::getenv("DM_SOIL_CACHE");
  if (!dir || !*dir) return std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, hooks);
  const std::string path = PreparedSoilPath(dir, y, inputs.Files(), vehicle);
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const std::string state = OpenSealedState(path, kSoilMagic, kSoilFormat, "prepared soil");
      std::istringstream in(state, std::ios::binary);
      StateReader r(&in, path, state.size());
      auto t = std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, r);
      if (r.left() != 0) r.Fail(detail::Concat(r.left(), " bytes more than the soil holds"));
      t->SetPreparedFrom(path, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      return t;
    } catch (const ConfigError& e) {
      std::fprintf(stderr, "dem_soil: the prepared soil does not read (%s): preparing it again\n", e.what());
    }
  }
  auto t = std::make_unique<DemSoilTerrain>(p, vehicle.tire, vehicle.wheels, hooks);
  try {
    std::filesystem::create_directories(dir, ec);
    std::ostringstream os(std::ios::binary);
    StateWriter w(&os);
    t->SaveState(w);
    WriteFileAtomically(path, SealState(kSoilMagic, kSoilFormat, os.str()));
  } catch (const ConfigError& e) {  // (the run goes on without the cache)
    std::fprintf(stderr, "dem_soil: the prepared soil is not kept (%s)\n", e.what());
  }
  return t;
}

void CheckDemSoilTerrain(const YamlReader& y, const TerrainVehicle& vehicle) { ReadDemSoilFor(y, vehicle); }

TerrainDescription DescribeDemSoilTerrain(const YamlReader& y) {
  return SoilDescription(DemSoilParams::Read(y));
}

template <class Ar>
void DemSoilBin::Io(Ar& ar) {
  ar.Tag("soil_bin");
  dem_->Io(ar);
  prep_->Io(ar);
  ar(centres_, surface_, shift_, watch_, watch_every_, watch_start_, watch_plastic_);
  if constexpr (Ar::kLoading)
    if (centres_.size() != tire_walls_.size()) ar.Fail("the tires' centres do not match the tires");
}
template void DemSoilBin::Io(StateWriter&);
template void DemSoilBin::Io(StateReader&);

template <class Ar>
void DemSoilTerrain::Io(Ar& ar) {
  ar.Tag("dem_soil_terrain");
  {
    // what soil it is (a checkpoint of another soil stops here, naming both)
    const DemSoilParams& p = bin_->params();
    const std::string what = detail::Concat("level ", p.level.name, ", d ", p.level.particle_diameter, " m, bin ",
                                            p.level.length, " x ", p.level.width, " m, f ", p.cohesion_factor, ", mu ",
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
