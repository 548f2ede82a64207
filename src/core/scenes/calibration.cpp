#include "dem_mobility/core/scenes/calibration.h"

#include <algorithm>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

namespace {
double Interpolate(const std::vector<double>& x, const std::vector<double>& y, double v) {
  const auto it = std::upper_bound(x.begin(), x.end(), v);
  const size_t k = std::min<size_t>(std::max<size_t>(it - x.begin(), 1), x.size() - 1);
  const double s = (v - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] + s * (y[k] - y[k - 1]);
}
}  // namespace

CiCalibration CiCalibration::Read(const YamlReader& y) {
  CiCalibration c;
  c.file = y.file();
  c.friction = y.DoubleIn("friction", 0.0, 5.0);
  c.level = y.String("fidelity", "");
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
  // what the sweep wrote for people: where it came from and the runs behind it
  for (const char* key : {"scene", "date", "method"}) y.String(key, "");
  if (y.Has("runs")) y.Table("runs");
  y.Finish();
  return c;
}

CiCalibration CiCalibration::Load(const std::string& path) { return Read(YamlReader::Load(path)); }

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
