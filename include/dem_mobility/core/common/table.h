// Piecewise-linear lookup tables (force tables, engine curves, soil curves).
#pragma once

#include <string>
#include <vector>

namespace dem_mobility::core {

/// y(x) by linear interpolation between points with strictly increasing x; held constant outside.
class Table1D {
 public:
  Table1D() = default;
  /// Throws ConfigError (naming `what`) unless x is strictly increasing, sizes match and size >= 1.
  Table1D(std::vector<double> x, std::vector<double> y, const std::string& what = "table");

  double operator()(double x) const {  // (the ends inline: the DEM step looks up a table per particle, mostly at an end)
    if (x <= x_.front()) return y_.front();
    if (x >= x_.back()) return y_.back();
    return Between(x);
  }
  /// Integral of y from x0 to x1 (with the constant extension outside the table).
  double Integral(double x0, double x1) const;
  /// Largest |dy/dx| over the table's segments.
  double MaxSlope() const;
  bool empty() const { return x_.empty(); }
  const std::vector<double>& x() const { return x_; }
  const std::vector<double>& y() const { return y_; }

 private:
  /// y(x) for x_.front() < x < x_.back() (or x NaN: NaN).
  double Between(double x) const;
  double IntegralFromFirst(double x) const;
  std::vector<double> x_, y_;
};

}  // namespace dem_mobility::core
