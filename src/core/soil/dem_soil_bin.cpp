#include "dem_mobility/core/soil/dem_soil_bin.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/state_archive.h"
#include "dem_mobility/core/dem/dem_shapes.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {

/// The soil's bands across y (the whole width, or a strip under each wheel track) in the bin's
/// frame (y from its side wall), checked against the tire and the bin.
std::vector<std::pair<double, double>> BinBands(const DemSoilParams& p, const TireGeometry& tire) {
  const SoilBinLevel& l = p.level;
  const double d = l.particle_diameter;
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
  return bands;
}

/// The poured particles' places in the bin's frame: one lattice over the width, or each strip
/// poured between its own walls, its lattice centred between them, half the soil each.
std::vector<Vector3d> BinLattice(const DemSoilParams& p, const std::vector<std::pair<double, double>>& bands) {
  const SoilBinLevel& l = p.level;
  const double d = l.particle_diameter;
  if (bands.size() == 1)
    return PourLattice(
        p.ParticleCount(), d, 1.1, {0.0, 0.0}, {l.length, l.width},
        [&](double x, double y) { return x >= 0.6 * d && x <= l.length - 0.6 * d && y >= 0.6 * d && y <= l.width - 0.6 * d; },
        p.seed, /*spread_last_layer=*/p.patch.enabled);  // a vehicle's patch: level across its width
  std::vector<Vector3d> lattice;
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
  return lattice;
}

/// The container in the bin's frame: an open box (a moving patch's floor and sides reach over the
/// whole travel: their material stays put) and, with strips, each strip between walls of its own
/// (from the floor to the box's height) and a rigid floor over the rest of the width, between the
/// strips and beside them: 1.5 d below the bed's nominal surface (soil spilled onto it passes under
/// the leveling plate), and kept half a diameter from the strips' walls (a particle inside a strip
/// never reaches its edge: pressed by the wall and by the floor's edge, it would be pushed twice).
std::vector<DemWall> BinContainer(const DemSoilParams& p, const std::vector<std::pair<double, double>>& bands,
                                  double wall_height) {
  const SoilBinLevel& l = p.level;
  const double d = l.particle_diameter;
  const double reach = p.patch.enabled ? l.length + p.patch.travel : l.length;
  std::vector<DemWall> box = MakeOpenBoxWalls(reach, l.width, wall_height);
  box[2] = MakeQuadWall("x1", {l.length, 0, 0}, {0, l.width, 0}, {0, 0, wall_height});
  if (bands.size() == 1) return box;
  std::vector<double> edges = {0.0};
  for (const auto& b : bands) {
    // (none where a strip's side is the box's: two walls there would press the soil twice)
    if (b.first > 1e-9) box.push_back(MakeQuadWall("strip_side", {0, b.first, 0}, {reach, 0, 0}, {0, 0, wall_height}));
    if (b.second < l.width - 1e-9)
      box.push_back(MakeQuadWall("strip_side", {0, b.second, 0}, {reach, 0, 0}, {0, 0, wall_height}));
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
  return box;
}

/// Tire k of `wheels`, parked high above the bin (corner `o`) until a wheel state puts it somewhere.
DemWall BinTireWall(const DemSoilParams& p, const TireGeometry& tire, int k, int wheels, const Vector3d& o,
                    double wall_height) {
  const SoilBinLevel& l = p.level;
  DemWall w;
  w.name = wheels == 1 ? std::string("tire") : std::string("tire_") + (k < kWheels ? kWheelNames[k] : std::to_string(k));
  w.mesh = tire.soil_mesh;
  w.friction = p.tire_friction;
  w.adhesion_factor = p.tire_adhesion;
  w.fast = true;
  w.margin = p.wall_margin;
  w.position = o + Vector3d(0.5 * l.length + 3.0 * k, 0.5 * l.width, wall_height + 10.0 + tire.radius);
  w.wrench_point = w.position;
  return w;
}

/// The moving patch's leveling cylinder (axis along y) and plate, parked above until it starts.
std::pair<DemWall, DemWall> BinLevelingTools(const DemSoilParams& p, const Vector3d& o, double wall_height) {
  const SoilBinLevel& l = p.level;
  const double span = l.width - l.particle_diameter;
  DemWall c = MakeRodWall("leveling_cylinder", p.patch.leveling_radius, span, 16);
  for (Vector3d& v : c.mesh.vertices) v = Vector3d(v.x(), -v.z() + 0.5 * span, v.y());
  c.fast = true;
  c.friction = p.tire_friction;
  c.position = o + Vector3d(0.5 * l.length, 0.5 * l.width, wall_height + 20.0);
  DemWall pl = MakeQuadWall("leveling_plate", Vector3d(0, -0.5 * span, 0), Vector3d(p.patch.plate_length, 0, 0),
                            Vector3d(0, span, 0));
  pl.fast = true;
  pl.friction = p.tire_friction;
  pl.position = o + Vector3d(0.5 * l.length, 0.5 * l.width, wall_height + 25.0);
  return {std::move(c), std::move(pl)};
}

}  // namespace

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
  const std::vector<std::pair<double, double>> bands = BinBands(p, tire);
  const std::vector<Vector3d> lattice = BinLattice(p, bands);
  double top = 0.0;
  for (const Vector3d& x : lattice) top = std::max(top, x.z());
  wall_height_ = top + 2.0 * d;
  for (DemWall& w : BinContainer(p, bands, wall_height_)) {
    for (Vector3d& v : w.mesh.vertices) v += o;
    container_.push_back(s.AddWall(std::move(w)));
  }
  DemWall lid = MakeQuadWall("lid", Vector3d(0, 0, 0), Vector3d(l.length, 0, 0), Vector3d(0, l.width, 0));
  for (Vector3d& v : lid.mesh.vertices) v += Vector3d(o.x(), o.y(), 0.0);
  lid.position = Vector3d(0, 0, o.z() + top + d);
  lid_ = s.AddWall(std::move(lid));
  for (int k = 0; k < wheels; ++k) {
    DemWall w = BinTireWall(p, tire, k, wheels, o, wall_height_);
    centres_.push_back(w.position);
    tire_walls_.push_back(s.AddWall(std::move(w)));
  }
  if (p.patch.enabled) {
    auto [cylinder, plate] = BinLevelingTools(p, o, wall_height_);
    cylinder_ = s.AddWall(std::move(cylinder));
    plate_ = s.AddWall(std::move(plate));
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
  DescribeRest(prep_->rest(), "soil_settle_", r);
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

}  // namespace dem_mobility::core
