#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/common/state_archive.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

namespace {
constexpr double kToolLowering = 0.5;  ///< [m/s] the leveling tools' descent to their working height
}  // namespace

SoilPatch::SoilPatch(DemSoilBin* bin, const SoilPatchParams& p, unsigned seed)
    : bin_(bin), p_(p), rng_(0x5eed0000ULL + seed) {
  DM_THROW_UNLESS(p.enabled && bin->prepared() && bin->leveling_plate() >= 0, "SoilPatch: the bin has no patch or is not prepared");
  const DemSoilParams& bp = bin->params();
  const DemSystem& dem = bin->dem();
  d_ = bp.level.particle_diameter;
  bed_length_ = bp.level.length;
  width_ = bp.level.width;
  floor_z_ = bin->floor_z();
  const double rear = bp.origin.x();
  front_x0_ = rear + bed_length_;
  n0_ = dem.size();
  walls_y_ = bp.SoilBands();
  for (const auto& b : walls_y_) {
    bands_.emplace_back(b.first + 1.5 * d_, b.second - 1.5 * d_);
    band_width_ += bands_.back().second - bands_.back().first;
  }
  // the bed's surface and depth, away from the end walls
  depth0_ = 1.0;  // (Measure's density layer needs a depth; the surface does not)
  const PatchSoilMeasure bed = Measure(rear + std::min(0.5, 0.1 * bed_length_), front_x0_ - std::min(0.5, 0.1 * bed_length_));
  DM_THROW_UNLESS(std::isfinite(bed.surface) && bed.surface > floor_z_ + d_, "SoilPatch: the bed has no surface");
  surface0_ = bed.surface;
  depth0_ = surface0_ - floor_z_;
  // the sphere holds the whole bed: nothing leaves before the patch moves
  centre0_ = Vector3d(rear + 0.5 * bed_length_, 0.0, floor_z_ + 0.5 * depth0_);
  centre_ = centre0_;
  radius_ = std::sqrt(0.25 * bed_length_ * bed_length_ + 0.25 * width_ * width_ +
                      std::pow(0.5 * depth0_ + d_, 2)) + p.sphere_margin;
  template_length_ = std::min(p.template_length, bed_length_ / 3.0);
  prev_layer_first_id_ = layer_first_id_ = n0_;
}

SoilPatch::SoilPatch(const SoilPatch& o, DemSoilBin* bin) : SoilPatch(o) { bin_ = bin; }

SoilPatch::SoilPatch(DemSoilBin* bin, const SoilPatchParams& p, StateReader& in) : bin_(bin), p_(p) {
  DM_THROW_UNLESS(p.enabled && bin->prepared() && bin->leveling_plate() >= 0, "SoilPatch: the bin has no patch or is not prepared");
  Io(in);
}

void SoilPatch::CaptureTemplate() {
  // the slice of the bed just behind its front wall (ahead of the front wheels and of the
  // leveling tools' reach when the patch starts to follow), as the soil is then
  const DemSystem& dem = bin_->dem();
  const double xa = front_x0_ - std::min(0.3, 0.05 * bed_length_) - template_length_;
  sites_.clear();
  dem.ForEachParticle([&](int id, const Vector3d& x, const Vector3d&) {
    if (x.x() >= xa && x.x() < xa + template_length_)
      sites_.push_back({Vector3d(x.x() - xa, x.y(), x.z()), dem.plastic_deformation(id)});
  });
  if (sites_.empty())
    throw SimulationError("dem_soil patch (" + bin_->params().file + "): no soil in the emitter's template slice");
  std::sort(sites_.begin(), sites_.end(), [](const Site& a, const Site& b) {
    if (a.x.x() != b.x.x()) return a.x.x() < b.x.x();
    if (a.x.y() != b.x.y()) return a.x.y() < b.x.y();
    return a.x.z() < b.x.z();
  });
  min_site_x_ = sites_.front().x.x();
  layer_begin_.clear();
  for (size_t i = 0; i < sites_.size(); ++i) {
    const int layer = static_cast<int>(std::floor((sites_[i].x.x() - min_site_x_) / d_));
    while (static_cast<int>(layer_begin_.size()) <= layer) layer_begin_.push_back(static_cast<int>(i));
  }
  layer_begin_.push_back(static_cast<int>(sites_.size()));
  // the period of the copies: the shift (about the slice's length) at which the next copy's first
  // layers clash least with the last ones of the copy before (fewest sites closer than the
  // clearance, per length of soil laid); the slice's cut is no plane the soil fits across at
  // every shift
  const int layers = static_cast<int>(layer_begin_.size()) - 1;
  const int head = layer_begin_[std::min(2, layers)], tail = layer_begin_[std::max(0, layers - 2)];
  const double c2 = std::pow(p_.seam_clearance * d_, 2);
  double best = -1.0;
  for (int k = -12; k <= 6; ++k) {
    const double period = template_length_ + k * 0.05 * d_;
    int clash = 0;
    for (int i = 0; i < head; ++i) {
      const Vector3d a = sites_[i].x + Vector3d(period, 0, 0);
      for (int j = tail; j < static_cast<int>(sites_.size()); ++j)
        if ((sites_[j].x - a).squaredNorm() < c2) {
          ++clash;
          break;
        }
    }
    // particles laid per length of soil: the most wins
    const double laid = (static_cast<double>(sites_.size()) - clash) / period;
    if (laid > best) {
      best = laid;
      period_ = period;
      seam_clash_ = clash;
    }
  }
}

double SoilPatch::emitter_from() const {
  return layer_ < 0 ? front_x0_ : copy_origin_ + min_site_x_ + layer_ * d_;
}
double SoilPatch::emitter_to() const { return layer_ < 0 ? front_x0_ : emitter_from() + d_; }

PatchSoilMeasure SoilPatch::Measure(double x0, double x1) const {
  PatchSoilMeasure m;
  const DemSystem& dem = bin_->dem();
  const double ymax = 0.5 * width_ - 1.5 * d_, cell = 2.0 * d_, y0 = bin_->params().origin.y();
  const int nx = std::max(1, static_cast<int>(std::floor((x1 - x0) / cell)));
  const int ny = std::max(1, static_cast<int>(std::floor(2.0 * ymax / cell)));
  const double cx = (x1 - x0) / nx, cy = 2.0 * ymax / ny;
  std::vector<double> top(static_cast<size_t>(nx) * ny, -std::numeric_limits<double>::infinity());
  const double z_layer = floor_z_ + 0.75 * depth0_;
  int counted = 0, reemitted = 0;
  dem.ForEachParticle([&](int id, const Vector3d& x, const Vector3d&) {
    if (!(x.x() >= x0 && x.x() < x1 && InSoil(x.y() - y0))) return;
    const int ix = std::min(nx - 1, static_cast<int>((x.x() - x0) / cx));
    const int iy = std::min(ny - 1, static_cast<int>((x.y() - y0 + ymax) / cy));
    double& t = top[static_cast<size_t>(ix) * ny + iy];
    t = std::max(t, x.z());
    if (x.z() < z_layer) ++counted;
    ++m.particles;
    if (id >= n0_) ++reemitted;
  });
  double sum = 0.0;
  int columns = 0;
  for (double t : top)
    if (std::isfinite(t)) {
      sum += t + 0.5 * d_;
      ++columns;
    }
  if (columns > 0) m.surface = sum / columns;
  m.density = counted * dem.mass() / ((x1 - x0) * band_width_ * 0.75 * depth0_);
  m.reemitted_fraction = m.particles > 0 ? static_cast<double>(reemitted) / m.particles : 0.0;
  return m;
}

void SoilPatch::StartCopy() {
  if (stats_.copies == 0) {
    // the first copy against the bed's face; template sites too near the soil already there are
    // skipped as they come (Blocked). On a grade the bed slumps downhill, away from where its front
    // wall stood (at the tiny level by 1.5 d in 5 s at 12 deg), and a copy laid at the wall left a
    // seam of 0.7-0.8 of the bed's density. Laid too far back it is no better: its sites clash with
    // the face's particles and are skipped too sparsely to fill the gaps between them (0.86 with the
    // face at its columns' 5th percentile). The face: per column (y and z cells a diameter wide,
    // away from the side walls and below the surface layer) its foremost particle, and of these
    // the median (the 25th to 80th percentiles gave a seam of 0.93-0.95, as between two copies)
    const double y0 = bin_->params().origin.y(), ztop = surface0_ - d_;
    std::map<std::pair<long, long>, double> columns;
    bin_->dem().ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
      if (x.x() < front_x0_ - 1.0 || x.x() > front_x0_ + 2.0 * d_ || !InSoil(x.y() - y0) || x.z() > ztop) return;
      const std::pair<long, long> key(std::lround(std::floor((x.y() - y0) / d_)),
                                      std::lround(std::floor((x.z() - floor_z_) / d_)));
      auto it = columns.emplace(key, x.x()).first;
      it->second = std::max(it->second, x.x());
    });
    const double at_wall = front_x0_ - 0.5 * d_;
    double face = at_wall;
    if (!columns.empty()) {
      std::vector<double> fronts;
      fronts.reserve(columns.size());
      for (const auto& c : columns) fronts.push_back(c.second);
      const auto median = fronts.begin() + static_cast<long>(fronts.size() / 2);
      std::nth_element(fronts.begin(), median, fronts.end());
      face = std::min(face, *median);
    }
    stats_.face_setback = at_wall - face;
    copy_origin_ = face + 0.4 * d_ - min_site_x_;
  } else {
    copy_origin_ += period_;
  }
  ++stats_.copies;
}

void SoilPatch::GatherZone() {
  zone_.clear();
  const double lo = emitter_from() - 1.5 * d_, hi = emitter_to() + 1.5 * d_;
  bin_->dem().ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
    if (x.x() > lo && x.x() < hi) zone_.push_back(x);
  });
}

void SoilPatch::NextLayer() {
  const int layers = static_cast<int>(layer_begin_.size()) - 1;
  ++layer_;
  if (stats_.copies == 0 || layer_ >= layers) {
    StartCopy();
    layer_ = 0;
  }
  // the layer is laid from the bottom up: its free sites by height
  free_.clear();
  for (int i = layer_begin_[layer_]; i < layer_begin_[layer_ + 1]; ++i) free_.push_back(i);
  std::stable_sort(free_.begin(), free_.end(), [&](int a, int b) { return sites_[a].x.z() < sites_[b].x.z(); });
  // the layer before the last one laid is let go: the last one now holds it in front, as the bed
  // held its neighbours (a freshly laid face, free, would relax and settle into the next layer's
  // sites while that layer is laid, bottom up, and block them: at 3 m/s 8 % of the soil was lost)
  DemSystem& dem = bin_->dem();
  for (int id = prev_layer_first_id_; id < layer_first_id_; ++id)
    if (dem.alive(id)) dem.set_held(id, false);
  prev_layer_first_id_ = layer_first_id_;
  layer_first_id_ = bin_->dem().size();
  GatherZone();
}

bool SoilPatch::Blocked(const Vector3d& x) const {
  const double c2 = std::pow(p_.seam_clearance * d_, 2);
  for (const Vector3d& z : zone_)
    if ((z - x).squaredNorm() < c2) return true;
  return false;
}

void SoilPatch::Emit() {
  for (;;) {
    if (free_.empty()) NextLayer();
    // a random free site among the lowest ones (within a diameter of the lowest)
    const double z_low = sites_[free_.front()].x.z();
    size_t m = 1;
    while (m < free_.size() && sites_[free_[m]].x.z() < z_low + d_) ++m;
    const size_t k = static_cast<size_t>(rng_() % m);
    const Site s = sites_[free_[k]];
    free_.erase(free_.begin() + static_cast<long>(k));
    const Vector3d x(copy_origin_ + s.x.x(), s.x.y(), s.x.z());
    if (Blocked(x)) {  // soil already there (a seam, or a particle that fell or was thrown)
      ++stats_.skipped_sites;
      continue;
    }
    DemSystem& dem = bin_->dem();
    const int id = dem.AddParticle(x);
    dem.set_plastic_deformation(id, s.plastic);
    dem.set_held(id, true);  // until the layer after next starts (NextLayer)
    zone_.push_back(x);
    ++stats_.reemitted;
    return;
  }
}

bool SoilPatch::InSoil(double y) const {
  for (const auto& b : bands_)
    if (y > b.first && y < b.second) return true;
  return false;
}

double SoilPatch::ToolWorkingHeight() const { return surface0_ + p_.leveling_clearance * d_; }

void SoilPatch::PlaceTools(double velocity) {
  DemSystem& dem = bin_->dem();
  const double x = centre_.x() + tool_offset_;
  // the tools are lowered to their working height at kToolLowering (they start on the highest
  // particle under them: set down at once they would land inside the particles that stand above
  // the bed's mean surface and throw them out)
  const double target = ToolWorkingHeight();
  const double lowering = tool_z_ > target ? std::min(kToolLowering, (tool_z_ - target) / dem.dt()) : 0.0;
  tool_z_ -= lowering * dem.dt();
  const double z = tool_z_;
  DemWall& c = dem.mutable_wall(bin_->leveling_cylinder());
  c.position = Vector3d(x, 0.0, z + p_.leveling_radius);
  c.velocity = Vector3d(velocity, 0.0, -lowering);
  c.wrench_point = c.position;
  DemWall& pl = dem.mutable_wall(bin_->leveling_plate());
  pl.position = Vector3d(x - p_.plate_length, 0.0, z);
  pl.velocity = Vector3d(velocity, 0.0, -lowering);
  pl.wrench_point = pl.position;
}

void SoilPatch::Check(double front_wheels_x) {
  const PatchSoilMeasure m = Measure(front_wheels_x + p_.check_from, front_wheels_x + p_.check_to);
  if (m.particles == 0 || !stats_.following) return;
  const double ratio = m.density / stats_.initial.density, offset = m.surface - stats_.initial.surface;
  stats_.log.push_back({bin_->dem().time(), front_wheels_x, ratio, offset, m.reemitted_fraction, m.particles});
  if (m.reemitted_fraction < 0.9) return;
  ++stats_.checks;
  ratio_sum_ += ratio;
  offset_sum_ += offset;
  stats_.density_ratio_mean = ratio_sum_ / stats_.checks;
  stats_.surface_offset_mean = offset_sum_ / stats_.checks;
  stats_.density_ratio_min = stats_.checks == 1 ? ratio : std::min(stats_.density_ratio_min, ratio);
  stats_.density_ratio_max = stats_.checks == 1 ? ratio : std::max(stats_.density_ratio_max, ratio);
  stats_.surface_offset_max = stats_.checks == 1 ? std::abs(offset) : std::max(stats_.surface_offset_max, std::abs(offset));
}

void SoilPatch::BeforeStep(const std::vector<Vector3d>& wheels) {
  DM_THROW_UNLESS(wheels.size() >= 2, "SoilPatch: ", wheels.size(), " wheels");
  DemSystem& dem = bin_->dem();
  const double dt = dem.dt();
  double centroid = 0.0;
  for (const Vector3d& w : wheels) centroid += w.x();
  centroid /= wheels.size();
  const double front = 0.5 * (wheels[0].x() + wheels[1].x());
  // a wheel past the side walls is off the soil: the run cannot go on as a run on this soil
  const DemSoilParams& bp = bin_->params();
  const double half_tire = 0.5 * bin_->tire().width;
  for (size_t i = 0; i < wheels.size(); ++i) {
    const double y = wheels[i].y() - bp.origin.y();
    bool on = false;
    for (const auto& b : walls_y_) on = on || (y >= b.first + half_tire && y <= b.second - half_tire);
    if (!on)
      throw SimulationError(detail::Concat(
          "dem_soil patch (", bp.file, "): wheel ", wheels.size() == kWheels ? kWheelNames[i] : std::to_string(i),
          " is at y = ", wheels[i].y(), " m, off the soil (",
          bp.strip_width > 0.0 ? detail::Concat("strips ", bp.strip_width, " m wide at y = +-", bp.strip_offset, " m, track_strip_width")
                               : detail::Concat("the patch is ", width_, " m wide, levels.", bp.level.name, ".width"),
          "): the vehicle veered off its course"));
  }
  if (!started_) {
    started_ = true;
    tool_offset_ = front + p_.leveling_ahead - centre0_.x();
    check_every_ = std::max(1L, std::lround(p_.check_period / dt));
    // the tools start on the highest particle under them (plate and cylinder, a diameter around)
    const double x_cyl = centre_.x() + tool_offset_;
    const double xa = x_cyl - p_.plate_length - d_, xb = x_cyl + p_.leveling_radius + d_;
    tool_z_ = ToolWorkingHeight();
    dem.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
      if (x.x() > xa && x.x() < xb) tool_z_ = std::max(tool_z_, x.z() + 0.5 * d_);
    });
    PlaceTools(0.0);
  }
  if (!stats_.following && centroid >= centre0_.x()) {
    stats_.following = true;
    // the soil as the vehicle meets it when the patch starts: the template the emitter lays down
    // and the bed its checks compare with (the released bed still relaxes for a while)
    CaptureTemplate();
    stats_.initial = Measure(front + p_.check_from, front + p_.check_to);
    // the bin's front wall goes: the emitter lays the soil down beyond it from now on
    DemWall& fw = dem.mutable_wall(bin_->container_walls()[2]);
    fw.position.z() += 1000.0;
  }
  if (stats_.following) {
    const double x = std::max(centre_.x(), centroid);
    const double v = (x - centre_.x()) / dt;
    centre_.x() = x;
    PlaceTools(v);
    if (std::max(box_front(), emitter_to()) > front_x0_ + p_.travel - 2.0 * d_)
      throw SimulationError(detail::Concat("dem_soil patch (", bin_->params().file, "): the patch reached x = ",
                                           box_front(), " m, the end of its floor (patch.travel = ", p_.travel,
                                           " m beyond the bin's front at ", front_x0_, " m)"));
  }
  // what left the sphere, and strays in the emitter's zone, in storage order (the same for any
  // thread count)
  std::vector<int>& out = leaving_;
  out.clear();
  const double r2 = radius_ * radius_;
  const bool emitting = layer_ >= 0;
  const double zone_from = emitter_from() - 0.25 * d_, zone_to = emitter_to() + d_;
  const double near_lo = emitter_from() - 1.5 * d_, near_hi = emitter_to() + 1.5 * d_;
  zone_.clear();
  // (only the sphere's rear half removes soil: the soil the emitter lays down ahead, a little less
  // dense than the soil leaving at the rear, would otherwise reach past the sphere's front, leave
  // at once and be laid further ahead, without end)
  const double sphere_to = centre_.x();
  // (and, once the patch follows, the bed's bottom layer in the middle half of the box, away from
  // its faces (the rear one, left free as the soil behind it leaves, slumps; the laid front
  // settles): does the bed slide down the grade on the floor?)
  const double z_bottom = floor_z_ + d_, slide_lo = centre_.x() - 0.25 * bed_length_, slide_hi = centre_.x() + 0.25 * bed_length_;
  dem.ForEachParticle([&](int id, const Vector3d& x, const Vector3d& v) {
    if (stats_.following && x.z() < z_bottom && x.x() > slide_lo && x.x() < slide_hi) {
      bed_vx_sum_ += v.x();
      ++bed_vx_count_;
    }
    if (x.x() < sphere_to && (x - centre_).squaredNorm() > r2) {
      out.push_back(id);
    } else if (stats_.following && (x.x() > zone_to || (emitting && x.x() >= zone_from && id < prev_layer_first_id_))) {
      out.push_back(id);
      ++stats_.strays;
    } else if (x.x() > near_lo && x.x() < near_hi) {
      zone_.push_back(x);
    }
  });
  for (int id : out) dem.RemoveParticle(id);
  for (size_t k = 0; k < out.size(); ++k) Emit();
  ++steps_;
  if (steps_ % check_every_ == 0) {
    Check(front);
    if (bed_vx_count_ > 0) {
      const double down = -bed_vx_sum_ / bed_vx_count_;
      stats_.bed_slide_speed_max = std::max(stats_.bed_slide_speed_max, down);
      bed_vx_sum_ = 0.0;
      bed_vx_count_ = 0;
    }
  }
}

void WritePatchChecks(const PatchStats& s, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the patch's checks");
  out << "t,front_x,density_ratio,surface_offset,reemitted_fraction,particles\n" << std::setprecision(8);
  for (const PatchCheck& c : s.log)
    out << c.t << "," << c.front_x << "," << c.density_ratio << "," << c.surface_offset << "," << c.reemitted_fraction
        << "," << c.particles << "\n";
}

template <class Ar>
void SoilPatch::Io(Ar& ar) {
  ar.Tag("soil_patch");
  ar(rng_, d_, bed_length_, width_, floor_z_, surface0_, depth0_, front_x0_, template_length_, min_site_x_, walls_y_,
     bands_, band_width_, period_, seam_clash_, centre0_, centre_, radius_, n0_, sites_, layer_begin_, copy_origin_,
     layer_, free_, zone_, leaving_, prev_layer_first_id_, layer_first_id_, started_, tool_offset_, tool_z_,
     front_offset_, steps_, check_every_, bed_vx_sum_, bed_vx_count_, ratio_sum_, offset_sum_, stats_);
  if constexpr (Ar::kLoading) {
    for (size_t k = 0; k < layer_begin_.size(); ++k)
      if (layer_begin_[k] < 0 || layer_begin_[k] > static_cast<int>(sites_.size()) ||
          (k > 0 && layer_begin_[k] < layer_begin_[k - 1]))
        ar.Fail("an emitter layer lies beyond the template");
    const int ids = bin_->dem().size();
    if (prev_layer_first_id_ < 0 || prev_layer_first_id_ > ids || layer_first_id_ < 0 || layer_first_id_ > ids ||
        n0_ < 0 || n0_ > ids)
      ar.Fail("the emitter's particles lie beyond the particles");
    for (int i : free_)
      if (i < 0 || i >= static_cast<int>(sites_.size())) ar.Fail("a free site lies beyond the template");
    if (layer_ >= 0 && layer_ + 1 >= static_cast<int>(layer_begin_.size())) ar.Fail("the emitter's layer is not one");
    if (check_every_ < 1) ar.Fail("the patch's check period is not one");
  }
}
template void SoilPatch::Io(StateWriter&);
template void SoilPatch::Io(StateReader&);

}  // namespace dem_mobility::core
