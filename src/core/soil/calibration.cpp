#include "dem_mobility/core/soil/calibration.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

namespace {

constexpr double kDiameterTolerance = 1e-6;  // relative, for LoadFor

double Interpolate(const std::vector<double>& x, const std::vector<double>& y, double v) {
  const auto it = std::upper_bound(x.begin(), x.end(), v);
  const size_t k = std::min<size_t>(std::max<size_t>(it - x.begin(), 1), x.size() - 1);
  const double s = (v - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] + s * (y[k] - y[k - 1]);
}

bool SameDiameter(double a, double b) { return std::abs(a - b) <= kDiameterTolerance * std::max(std::abs(a), std::abs(b)); }
bool SameFriction(double a, double b) { return std::abs(a - b) <= 1e-9 + 1e-6 * std::max(std::abs(a), std::abs(b)); }

std::string FlowList(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + detail::Concat(v[k]);
  return s + "]";
}

// A whole number read from a list of doubles (seeds, counts).
int WholeNumber(const YamlReader& y, const std::string& key, double v, int lo) {
  if (!(v == std::floor(v)) || v < lo || v > 2147483647.0)
    y.Fail(key, detail::Concat("expected whole numbers >= ", lo, ", found ", v));
  return static_cast<int>(v);
}

// provenance: where the table came from (all required but `scene_sha256` and `note`)
void ReadProvenance(const YamlReader& y, CiCalibration* c) {
  if (!y.Has("provenance"))
    y.Fail("provenance", "missing required key: a calibration table must say where it came from (commit, seeds, "
                         "soil_file, soil_sha256, scene_file, date, conditions)");
  const YamlReader p = y.Child("provenance");
  auto text = [&](const std::string& key) {
    const std::string v = p.String(key);
    if (v.empty()) p.Fail(key, "must not be empty");
    c->provenance.emplace_back(key, v);
    return v;
  };
  text("commit");
  const std::vector<double> seeds = p.DoubleList("seeds");
  if (seeds.empty()) p.Fail("seeds", "must list the seeds of the runs");
  for (double s : seeds) c->seeds.push_back(WholeNumber(p, "seeds", s, 0));
  c->provenance.emplace_back("seeds", FlowList(seeds));
  text("soil_file");
  const std::string sha = text("soil_sha256");
  if (sha.size() != 64 || !std::all_of(sha.begin(), sha.end(), [](char ch) { return std::isxdigit(static_cast<unsigned char>(ch)); }))
    p.Fail("soil_sha256", "expected the 64 hex digits of the soil file's sha256, found '" + sha + "'");
  text("scene_file");
  if (p.Has("scene_sha256")) text("scene_sha256");
  text("date");
  const YamlReader cond = p.Child("conditions");
  for (const char* key : {"container_diameter", "soil_depth", "cone_speed"})
    if (!cond.Has(key)) cond.Fail(key, "missing required key (the conditions the sweep was run at)");
  for (const std::string& key : cond.Keys()) {
    std::string v;
    if (key == "time_step_at") {  // the f values run at a step of their own: {f: dt}
      const YamlReader at = cond.Child(key);
      for (const std::string& f : at.Keys()) {
        v += (v.empty() ? "{" : ", ") + f + ": " + detail::Concat(at.DoubleIn(f, 1e-9, 1e-3));
      }
      at.Finish();
      c->provenance.emplace_back("conditions." + key, v + "}");
      continue;
    }
    try {
      v = detail::Concat(cond.Double(key));
    } catch (const ConfigError&) {
      v = FlowList(cond.DoubleList(key));  // a list (the CI window) or the error naming the key
    }
    c->provenance.emplace_back("conditions." + key, v);
  }
  cond.Finish();
  if (p.Has("note")) text("note");
  p.Finish();
}

// the measured points behind the table: per f, the mean CI over the seeds and its scatter
void ReadPoints(const YamlReader& y, CiCalibration* c) {
  if (!y.Has("points"))
    y.Fail("points", "missing required key: the mean and scatter of the CI over the seeds at each f");
  const YamlReader p = y.Child("points");
  const std::vector<double> f = p.DoubleList("f"), mean = p.DoubleList("ci_mean"), seeds = p.DoubleList("seeds");
  if (f.empty()) p.Fail("f", "must list at least one cohesion factor");
  if (mean.size() != f.size()) p.Fail("ci_mean", "must hold one value per f");
  if (seeds.size() != f.size()) p.Fail("seeds", "must hold one count per f");
  bool several = false;
  for (size_t k = 0; k < f.size(); ++k) {
    CiCalibration::Point q;
    q.f = f[k];
    q.ci_mean = mean[k];
    q.seeds = WholeNumber(p, "seeds", seeds[k], 1);
    q.ci_std = std::numeric_limits<double>::quiet_NaN();
    if (!(q.f > 0.0) || (k > 0 && !(q.f > f[k - 1]))) p.Fail("f", "must be positive and increasing");
    if (!(q.ci_mean > 0.0)) p.Fail("ci_mean", "cone indices must be > 0");
    if (q.seeds > static_cast<int>(c->seeds.size()))
      p.Fail("seeds", detail::Concat(q.seeds, " seeds at f = ", q.f, ", but provenance.seeds lists ", c->seeds.size()));
    several = several || q.seeds > 1;
    c->points.push_back(q);
  }
  if (several) {
    const std::vector<double> sd = p.DoubleList("ci_std");
    if (sd.size() != f.size()) p.Fail("ci_std", "must hold one value per f");
    for (size_t k = 0; k < sd.size(); ++k) {
      if (!(sd[k] >= 0.0)) p.Fail("ci_std", "must be >= 0");
      if (c->points[k].seeds > 1) c->points[k].ci_std = sd[k];
    }
  } else if (p.Has("ci_std")) {
    p.Fail("ci_std", "every point is a single seed, which has no scatter: leave ci_std out");
  }
  p.Finish();
}

void ReadErrorVsFinest(const YamlReader& y, CiCalibration* c) {
  if (!y.Has("error_vs_finest"))
    y.Fail("error_vs_finest", "missing required key: the level's CI error against the finest level run "
                              "({level, relative, note}; without a finer level, a note saying so)");
  const YamlReader e = y.Child("error_vs_finest");
  c->error_vs_finest.level = e.String("level");
  c->error_vs_finest.note = e.String("note", "");
  if (e.Has("relative")) {
    c->error_vs_finest.relative = e.DoubleIn("relative", -10.0, 10.0);
  } else {
    c->error_vs_finest.relative = std::numeric_limits<double>::quiet_NaN();
    if (c->error_vs_finest.note.empty())
      e.Fail("relative", "missing: give the relative error, or a note saying why it is not known");
  }
  e.Finish();
}

}  // namespace

CiCalibration CiCalibration::Read(const YamlReader& y) {
  CiCalibration c;
  c.file = y.file();
  if (!y.Has("particle_diameter"))
    y.Fail("particle_diameter", "missing required key: a calibration holds only for the particle size its sweep "
                                "was run at [m]");
  c.particle_diameter = y.DoubleIn("particle_diameter", 1e-4, 1.0);
  c.friction = y.DoubleIn("friction", 0.0, 5.0);
  c.level = y.String("fidelity");
  const Table1D t = y.Table("table");  // rows [CI, f]; strictly increasing CI is checked there
  c.ci = t.x();
  c.f = t.y();
  if (c.ci.size() < 2) y.Fail("table", "needs at least two rows [CI, f]");
  for (size_t k = 0; k < c.ci.size(); ++k) {
    if (!(c.ci[k] > 0.0)) y.Fail("table", "cone indices must be > 0");
    if (!(c.f[k] > 0.0)) y.Fail("table", "cohesion factors must be > 0");
    if (k > 0 && !(c.f[k] > c.f[k - 1])) y.Fail("table", "f must increase with CI");
  }
  // the fit the sweep wrote beside the table (for people; scenes interpolate in the table)
  if (y.DoubleList("cubic").size() != 4) y.Fail("cubic", "must hold 4 coefficients (CI^3, CI^2, CI, 1)");
  c.band = y.DoubleIn("band", 0.0, 10.0, 0.0);
  y.DoubleIn("cubic_residual", 0.0, 10.0, 0.0);  // how far the cubic misses the means (for people)
  y.String("method", "");
  ReadProvenance(y, &c);
  ReadPoints(y, &c);
  ReadErrorVsFinest(y, &c);
  // every run behind the points (for people): f, seed and CI columns
  if (y.Has("runs")) {
    const YamlReader r = y.Child("runs");
    const size_t n = r.DoubleList("f").size();
    if (r.DoubleList("seed").size() != n || r.DoubleList("ci").size() != n)
      r.Fail("", "f, seed and ci must be columns of the same length");
    r.Finish();
  }
  y.Finish();
  return c;
}

CiCalibration CiCalibration::Load(const std::string& path) { return Read(YamlReader::Load(path)); }

CiCalibration CiCalibration::LoadFor(const std::string& given, double particle_diameter, double friction) {
  namespace fs = std::filesystem;
  // config/scenes/../calibration -> config/calibration: the result names the table plainly
  std::string path = fs::path(given).lexically_normal().string();
  if (path.size() > 1 && path.back() == '/') path.pop_back();
  std::error_code ec;
  const auto wanted = [&] {
    return detail::Concat("particle_diameter ", particle_diameter, " m and friction ", friction);
  };
  if (!fs::is_directory(path, ec)) {
    if (!fs::exists(path, ec)) throw ConfigError(path + ": no such calibration table or directory");
    CiCalibration c = Load(path);
    if (!SameDiameter(c.particle_diameter, particle_diameter))
      throw ConfigError(detail::Concat(path, ": particle_diameter: the table was made for particles of ",
                                       c.particle_diameter, " m, not ", particle_diameter,
                                       " m: CI(f) depends on the particle size; run the cone sweep at ",
                                       particle_diameter, " m (dm-calibrate --fidelity LEVEL)"));
    if (!SameFriction(c.friction, friction))
      throw ConfigError(detail::Concat(path, ": friction: the table was made for mu ", c.friction, ", not ",
                                       friction, " (particle_diameter ", c.particle_diameter, " m)"));
    return c;
  }
  std::vector<std::string> files;
  for (const fs::directory_entry& e : fs::directory_iterator(path, ec))
    if (e.is_regular_file() && e.path().extension() == ".yaml") files.push_back(e.path().string());
  if (ec) throw ConfigError(path + ": cannot list the calibration directory: " + ec.message());
  std::sort(files.begin(), files.end());
  std::vector<CiCalibration> match;
  std::string available;
  for (const std::string& f : files) {
    CiCalibration c = Load(f);  // a bad table in the directory is an error, not skipped
    available += detail::Concat(available.empty() ? "" : ", ", fs::path(f).filename().string(), " (",
                                c.particle_diameter, " m, mu ", c.friction, ")");
    if (SameDiameter(c.particle_diameter, particle_diameter) && SameFriction(c.friction, friction))
      match.push_back(std::move(c));
  }
  if (match.empty())
    throw ConfigError(path + ": particle_diameter: no calibration table for " + wanted() +
                      "; run the cone sweep at that size (dm-calibrate --fidelity LEVEL). Tables here (particle_diameter, "
                      "friction): " + (available.empty() ? std::string("none") : available));
  if (match.size() > 1)
    throw ConfigError(path + ": particle_diameter: " + std::to_string(match.size()) + " tables hold for " + wanted() +
                      " (" + match[0].file + ", " + match[1].file + "): keep one per particle size and friction");
  return match[0];
}

void CiCalibration::Describe(ResultFile* r) const {
  r->Set("calibration_table", file);
  r->Set("calibration_level", level);
  r->Set("calibration_particle_diameter", particle_diameter);
  r->Set("calibration_friction", friction);
  r->Set("calibration_seeds", MinSeeds());
  // the table's scatter: its runs about the fit, and the worst point's spread over its seeds
  r->Set("calibration_band", band);
  double worst = -1.0;
  for (const Point& q : points)
    if (q.seeds > 1 && q.ci_mean > 0.0 && std::isfinite(q.ci_std)) worst = std::max(worst, q.ci_std / q.ci_mean);
  if (worst >= 0.0)
    r->Set("calibration_points_relative_std_max", worst);
  else
    r->Set("calibration_points_relative_std_max", "unknown: no point of the table has more than one seed");
  if (std::isfinite(error_vs_finest.relative))
    r->Set("calibration_error_vs_finest", error_vs_finest.relative);
  else
    r->Set("calibration_error_vs_finest", "unknown: " + error_vs_finest.note);
  r->Set("calibration_finest_level", error_vs_finest.level);
}

int CiCalibration::MinSeeds() const {
  int n = points.empty() ? 0 : points.front().seeds;
  for (const Point& p : points) n = std::min(n, p.seeds);
  return n;
}

double CiCalibration::CohesionFactor(double ci_psi) const {
  DM_THROW_UNLESS(ci_psi >= ci.front() && ci_psi <= ci.back(), file, ": cone index ", ci_psi,
                  " psi lies outside the calibrated range [", ci.front(), ", ", ci.back(), "] psi");
  return Interpolate(ci, f, ci_psi);
}

double CiCalibration::ConeIndex(double fac) const {
  DM_THROW_UNLESS(fac >= f.front() && fac <= f.back(), file, ": cohesion factor ", fac,
                  " lies outside the calibrated range [", f.front(), ", ", f.back(), "]");
  return Interpolate(f, ci, fac);
}

}  // namespace dem_mobility::core
