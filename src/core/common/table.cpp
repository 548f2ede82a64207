#include "dem_mobility/core/common/table.h"

#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

Table1D::Table1D(std::vector<double> x, std::vector<double> y, const std::string& what)
    : x_(std::move(x)), y_(std::move(y)) {
  DM_THROW_UNLESS(!x_.empty(), what, ": a table needs at least one point");
  DM_THROW_UNLESS(x_.size() == y_.size(), what, ": ", x_.size(), " x values but ", y_.size(),
                  " y values");
  for (size_t i = 0; i < x_.size(); ++i) {
    DM_THROW_UNLESS(std::isfinite(x_[i]) && std::isfinite(y_[i]), what, ": point ", i,
                    " is not finite");
    if (i > 0)
      DM_THROW_UNLESS(x_[i] > x_[i - 1], what, ": x must increase strictly, but point ", i, " has x = ",
                      x_[i], " after ", x_[i - 1]);
  }
}

double Table1D::Between(double x) const {
  // x_[i-1] < x < x_[i] (the first point above x). On the few points of the soil's and the
  // engine's curves, which the DEM step looks up per particle, a count of the inner points at or
  // below x: no branch on the data (a scan that stops at x is mispredicted once per lookup, as a
  // bisection is at each halving). A NaN x counts none: i = 1, and the result is NaN.
  size_t i = 1;
  if (x_.size() <= 16) {
    for (size_t k = 1; k + 1 < x_.size(); ++k) i += x_[k] <= x;
  } else {
    i = std::upper_bound(x_.begin(), x_.end(), x) - x_.begin();
  }
  const double t = (x - x_[i - 1]) / (x_[i] - x_[i - 1]);
  return y_[i - 1] + t * (y_[i] - y_[i - 1]);
}

double Table1D::IntegralFromFirst(double x) const {
  if (x <= x_.front()) return (x - x_.front()) * y_.front();
  double sum = 0.0;
  for (size_t i = 1; i < x_.size(); ++i) {
    if (x <= x_[i]) {
      const double yx = (*this)(x);
      return sum + 0.5 * (y_[i - 1] + yx) * (x - x_[i - 1]);
    }
    sum += 0.5 * (y_[i - 1] + y_[i]) * (x_[i] - x_[i - 1]);
  }
  return sum + (x - x_.back()) * y_.back();
}

double Table1D::Integral(double x0, double x1) const {
  return IntegralFromFirst(x1) - IntegralFromFirst(x0);
}

double Table1D::MaxSlope() const {
  double s = 0.0;
  for (size_t i = 1; i < x_.size(); ++i)
    s = std::max(s, std::abs((y_[i] - y_[i - 1]) / (x_[i] - x_[i - 1])));
  return s;
}

}  // namespace dem_mobility::core
