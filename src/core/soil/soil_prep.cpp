#include "dem_mobility/core/soil/soil_prep.h"
#include "dem_mobility/core/common/state_archive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_shapes.h"

namespace dem_mobility::core {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Vector3d> PourLattice(int count, double d, double spacing, const Vector2d& lo, const Vector2d& hi,
                                  const std::function<bool(double, double)>& inside, unsigned seed,
                                  bool spread_last_layer) {
  const double a = spacing * d;
  // the first site 0.6 d from the low walls; spread: the sites centred between the walls instead
  // (from the low wall, the rows leave up to a spacing more room at the high side)
  Vector2d first(lo.x() + 0.6 * d, lo.y() + 0.6 * d);
  if (spread_last_layer)
    for (int k = 0; k < 2; ++k) {
      const double room = hi[k] - lo[k] - 1.2 * d;
      first[k] += 0.5 * (room - std::floor(room / a + 1e-9) * a);
    }
  std::vector<Vector2d> layer;
  for (double y = first.y(); y <= hi.y() - 0.6 * d; y += a)
    for (double x = first.x(); x <= hi.x() - 0.6 * d; x += a)
      if (inside(x, y)) layer.emplace_back(x, y);
  DM_THROW_UNLESS(!layer.empty(), "the pour region holds no particle of diameter ", d);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.08 * d, 0.08 * d);
  std::vector<Vector3d> out;
  out.reserve(count);
  const int N = static_cast<int>(layer.size()), full = count / N * N, partial = count - full;
  for (int n = 0; n < count; ++n) {
    int site = n % N;
    if (spread_last_layer && n >= full)  // evenly spaced sites of the layer, not its first rows
      site = static_cast<int>((static_cast<long>(n - full) * 2 + 1) * N / (2L * partial));
    const Vector2d& p = layer[site];
    const int k = n / N;
    out.emplace_back(p.x() + jitter(rng), p.y() + jitter(rng), 0.6 * d + k * a + jitter(rng));
  }
  return out;
}

LidPress::LidPress(double target_force, double max_speed, double dt, double k_layer)
    : target_(target_force), v_max_(std::min(max_speed, 0.5 * target_force / (dt * k_layer))) {
  DM_THROW_UNLESS(target_force > 0.0 && max_speed > 0.0 && dt > 0.0 && k_layer > 0.0,
                  "lid: target force, speed, time step and layer stiffness must be > 0");
}

double LidPress::Velocity(double fz) const {
  return std::clamp(-v_max_ * (target_ - fz) / target_, -v_max_, v_max_);
}

LidHold::LidHold(DemSystem* s, int lid, double area, double pressure, double max_speed, Start start)
    : s_(s),
      lid_(lid),
      area_(area),
      start_(start),
      press_(pressure * area, max_speed, s->dt(),
             area / (s->soil().diameter * s->soil().diameter) * s->soil().NormalStiffness()) {}

void LidHold::Step() {
  DemWall& w = s_->mutable_wall(lid_);
  const double fz = w.force.z();  // the particles push the lid up
  const double v = press_.Velocity(fz);
  w.velocity = Vector3d(0, 0, v);
  w.position.z() += v * s_->dt();
  s_->Step();
  if (held_ < 0.0) {
    const double target = press_.target();
    const bool start = start_ == Start::kReaches95Percent ? fz >= 0.95 * target : std::abs(fz - target) <= 0.05 * target;
    if (start) held_ = 0.0;
  }
  if (held_ >= 0.0) {
    held_ += s_->dt();
    sum_pressure_ += s_->wall(lid_).force.z() / area_;
    sum_height_ += s_->wall(lid_).position.z();
    ++samples_;
  }
}

SoilPreparation::SoilPreparation(DemSystem* s, int lid, double area, double park_z, const SoilPreparationParams& p,
                                 const std::string& who)
    : s_(s), lid_(lid), area_(area), park_z_(park_z), p_(p), who_(who) {}

SoilPreparation::SoilPreparation(const SoilPreparation& o, DemSystem* s)
    : s_(s),
      lid_(o.lid_),
      area_(o.area_),
      park_z_(o.park_z_),
      p_(o.p_),
      who_(o.who_),
      phase_(o.phase_),
      phase_steps_(o.phase_steps_),
      height_poured_(o.height_poured_),
      height_consolidated_(o.height_consolidated_),
      rest_(o.rest_),
      rest_plastic0_(o.rest_plastic0_),
      rest_plastic_last_(o.rest_plastic_last_),
      ledger_before_(o.ledger_before_) {
  if (o.hold_) {
    hold_ = std::make_unique<LidHold>(*o.hold_);
    hold_->Rebind(s);
  }
}

const char* SoilPreparation::PhaseName(Phase p) {
  switch (p) {
    case Phase::kPour: return "pour";
    case Phase::kConsolidate: return "consolidate";
    case Phase::kRetreat: return "retreat";
    case Phase::kRelease: return "release";
    case Phase::kDone: return "done";
  }
  return "?";
}

std::string SoilPreparation::Detail() const {
  const double dt = s_->dt();
  char b[200];
  switch (phase_) {
    case Phase::kPour:
      std::snprintf(b, sizeof b, "settling before the lid, %.3f of %.3f s", phase_steps_ * dt, p_.settle_time);
      break;
    case Phase::kConsolidate: {
      const DemWall& w = s_->wall(lid_);
      const int n = std::clamp(std::snprintf(b, sizeof b, "lid at z = %.3f m, %.1f of %.1f kPa", w.position.z(),
                                             w.force.z() / area_ / 1e3, p_.lid_pressure / 1e3),
                               0, static_cast<int>(sizeof b) - 1);
      if (hold_ && hold_->holding())
        std::snprintf(b + n, sizeof b - n, ", held %.3f of %.3f s", hold_->held_time(), p_.hold_time);
      else
        std::snprintf(b + n, sizeof b - n, ", pressing for %.3f s", phase_steps_ * dt);
      break;
    }
    case Phase::kRetreat:
      std::snprintf(b, sizeof b, "lid rising, at z = %.3f m, %d particles touching it", s_->wall(lid_).position.z(),
                    s_->wall(lid_).contacts);
      break;
    case Phase::kRelease:
      std::snprintf(b, sizeof b, "settling without the lid, %.3f of %.3f s", phase_steps_ * dt, p_.release_time);
      break;
    case Phase::kDone:
      std::snprintf(b, sizeof b, "layer %.3f m high (%.3f m poured)", height_consolidated_, height_poured_);
      break;
  }
  return b;
}

void SoilPreparation::NextPhase(Phase next) {
  phase_ = next;
  phase_steps_ = 0;
}

void SoilPreparation::Step() {
  const double dt = s_->dt(), d = s_->soil().diameter;
  auto steps_of = [dt](double t) { return std::lround(t / dt); };
  switch (phase_) {
    case Phase::kPour:
      if (phase_steps_ < steps_of(p_.settle_time)) {
        s_->Step();
        ++phase_steps_;
      }
      if (phase_steps_ >= steps_of(p_.settle_time)) {
        height_poured_ = LayerHeight(*s_);
        s_->mutable_wall(lid_).position.z() = TopParticle(*s_) + 0.6 * d;  // just clear of the highest particle
        hold_ = std::make_unique<LidHold>(s_, lid_, area_, p_.lid_pressure, p_.lid_speed,
                                          LidHold::Start::kReaches95Percent);
        NextPhase(Phase::kConsolidate);
      }
      break;
    case Phase::kConsolidate:
      hold_->Step();
      ++phase_steps_;
      if (hold_->holding() && hold_->held_time() >= p_.hold_time) {
        NextPhase(Phase::kRetreat);
      } else if (!hold_->holding() && phase_steps_ * dt > p_.timeout) {
        throw SimulationError(detail::Concat(who_, ": the lid did not reach its pressure within ", p_.timeout, " s"));
      }
      break;
    case Phase::kRetreat: {
      // up at lid_speed until it is one diameter clear of every particle, then parked
      DemWall& w = s_->mutable_wall(lid_);
      w.velocity = Vector3d(0, 0, p_.lid_speed);
      w.position.z() += p_.lid_speed * dt;
      s_->Step();
      ++phase_steps_;
      if (s_->wall(lid_).position.z() > TopParticle(*s_) + 0.6 * d && s_->wall(lid_).contacts == 0) {
        w.velocity.setZero();
        w.position.z() = park_z_;
        NextPhase(Phase::kRelease);
      } else if (phase_steps_ * dt > p_.timeout) {
        throw SimulationError(
            detail::Concat(who_, ": the lid did not come free of the particles within ", p_.timeout, " s"));
      }
      break;
    }
    case Phase::kRelease:
      if (phase_steps_ == 0) WatchRest(true);
      if (phase_steps_ < steps_of(p_.release_time)) {
        s_->Step();
        ++phase_steps_;
        if (phase_steps_ % std::max(1L, steps_of(rest_.interval)) == 0) WatchRest(false);
      }
      if (phase_steps_ >= steps_of(p_.release_time)) {
        height_consolidated_ = LayerHeight(*s_);
        s_->set_plastic_ledger(ledger_before_);
        NextPhase(Phase::kDone);
      }
      break;
    case Phase::kDone: break;
  }
}

void SoilPreparation::WatchRest(bool first) {
  if (first) {  // the ledger on through the release (it only watches: the states are the same)
    ledger_before_ = s_->plastic_ledger();
    s_->set_plastic_ledger(true);
    rest_ = RestWatch();
    rest_plastic0_ = rest_plastic_last_ = s_->plastic_exchange();
    return;
  }
  const double t = phase_steps_ * s_->dt(), e = s_->plastic_exchange();
  rest_.median_speed = MedianParticleSpeed(*s_);
  // (the kinetic energy alone: DemSystem::Energy would also sum every contact's elastic energy)
  double v2 = 0.0;
  s_->ForEachParticle([&](int, const Vector3d&, const Vector3d& v) { v2 += v.squaredNorm(); });
  rest_.kinetic = 0.5 * s_->mass() * v2;
  rest_.kinetic_max = std::max(rest_.kinetic_max, rest_.kinetic);
  if (rest_.time_to_rest < 0.0 && rest_.median_speed < RestWatch::kRestSpeed) rest_.time_to_rest = t;
  rest_.plastic = e - rest_plastic0_;
  rest_.plastic_max_power = std::max(rest_.plastic_max_power, (e - rest_plastic_last_) / (t - rest_.watched));
  rest_plastic_last_ = e;
  rest_.watched = t;
  ++rest_.samples;
}

void DescribeRest(const RestWatch& w, const std::string& prefix, ResultFile* r) {
  r->Set(prefix + "median_speed", w.median_speed);
  r->Set(prefix + "time", w.time_to_rest);
  r->Set(prefix + "kinetic", w.kinetic);
  r->Set(prefix + "kinetic_max", w.kinetic_max);
  r->Set(prefix + "plastic_work", w.plastic);
  r->Set(prefix + "plastic_max_power", w.plastic_max_power);
  r->Set(prefix + "watched", w.watched);
}

double MedianParticleSpeed(const DemSystem& s) {
  std::vector<double> speed;
  speed.reserve(s.num_alive());
  s.ForEachParticle([&](int, const Vector3d&, const Vector3d& v) { speed.push_back(v.norm()); });
  if (speed.empty()) return 0.0;
  const auto mid = speed.begin() + static_cast<long>(speed.size() / 2);
  std::nth_element(speed.begin(), mid, speed.end());
  return *mid;
}

double LayerHeight(const DemSystem& s) {
  std::vector<double> z;
  z.reserve(s.size());
  s.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) { z.push_back(x.z()); });
  if (z.empty()) return 0.0;
  const size_t top = std::max<size_t>(1, z.size() / 20);
  std::partial_sort(z.begin(), z.begin() + top, z.end(), std::greater<double>());
  double sum = 0.0;
  for (size_t i = 0; i < top; ++i) sum += z[i];
  return sum / top + 0.5 * s.soil().diameter;
}

CylinderBed AddCylinderBed(DemSystem* s, double R, int count, int segments, unsigned seed) {
  const double d = s->soil().diameter;
  const std::vector<Vector3d> lattice = PourLattice(
      count, d, 1.1, {-R, -R}, {R, R}, [&](double x, double y) { return x * x + y * y <= (R - 0.6 * d) * (R - 0.6 * d); },
      seed);
  double top = 0.0;
  for (const Vector3d& x : lattice) top = std::max(top, x.z());
  CylinderBed bed;
  bed.wall_height = top + 2.0 * d;
  bed.floor = s->AddWall(MakeDiskWall("floor", 1.1 * R, segments));
  for (DemWall& w : MakeCylinderSideWalls("container", R, bed.wall_height, segments)) s->AddWall(std::move(w));
  DemWall lid = MakeDiskWall("lid", R, segments);
  lid.position = Vector3d(0, 0, top + d);
  bed.lid = s->AddWall(std::move(lid));
  for (const Vector3d& x : lattice) s->AddParticle(x);
  return bed;
}

int ReadThreads(const YamlReader& y) {
  const int threads = y.Int("threads", 1);
  if (threads < 1 || threads > 256) y.Fail("threads", "must lie in [1, 256]");
  return threads;
}

SoilParams ReadSceneSoil(const YamlReader& y, const std::string& kind) {
  const std::string scene = y.String("scene");
  if (scene != kind) y.Fail("scene", "expected '" + kind + "', found '" + scene + "'");
  return SoilParams::Read(YamlReader::Load(y.ResolvePath(y.String("soil"))));
}

double TopParticle(const DemSystem& s) {
  double top = 0.0;
  s.ForEachParticle([&](int, const Vector3d& x, const Vector3d&) { top = std::max(top, x.z()); });
  return top;
}

template <class Ar>
void SoilPreparation::Io(Ar& ar) {
  ar.Tag("preparation");
  ar(phase_, phase_steps_, height_poured_, height_consolidated_);
  rest_.Io(ar);
  ar(rest_plastic0_, rest_plastic_last_, ledger_before_);
  unsigned char has_hold = hold_ ? 1 : 0;
  ar(has_hold);
  if constexpr (Ar::kLoading) {
    if (static_cast<int>(phase_) < 0 || phase_ > Phase::kDone) ar.Fail("the preparation's phase is not one");
    if (!has_hold)
      hold_.reset();
    else if (!hold_)
      hold_ = std::make_unique<LidHold>(s_, lid_, area_, p_.lid_pressure, p_.lid_speed, LidHold::Start::kReaches95Percent);
  }
  if (hold_) hold_->Io(ar);
}
template void SoilPreparation::Io(StateWriter&);
template void SoilPreparation::Io(StateReader&);

}  // namespace dem_mobility::core
