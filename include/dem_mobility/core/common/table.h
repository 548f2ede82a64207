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

  double operator()(double x) const;
  /// Integral of y from x0 to x1 (with the constant extension outside the table).
  double Integral(double x0, double x1) const;
  /// Largest |dy/dx| over the table's segments.
  double MaxSlope() const;
  bool empty() const { return x_.empty(); }
  const std::vector<double>& x() const { return x_; }
  const std::vector<double>& y() const { return y_; }

 private:
  double IntegralFromFirst(double x) const;
  std::vector<double> x_, y_;
};

}  // namespace dem_mobility::core
