#include "dem_mobility/core/geometry/tire_geometry.h"

#include <cmath>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

TireGeometry TireGeometry::Make(double radius, double width, double shoulder_radius, int n_circ, int n_lat) {
  DM_THROW_UNLESS(radius > 0 && width > 0, "tire: radius and width must be positive");
  DM_THROW_UNLESS(shoulder_radius >= 0 && 2 * shoulder_radius <= width && shoulder_radius < radius,
                  "tire: shoulder_radius must be in [0, width/2]");
  DM_THROW_UNLESS(n_circ >= 8 && n_lat >= 2, "tire: need n_circ >= 8 and n_lat >= 2");
  TireGeometry g;
  g.radius = radius;
  g.width = width;
  g.shoulder_radius = shoulder_radius;
  g.n_circ = n_circ;
  g.n_lat = n_lat;
  const double flat = 0.5 * width - shoulder_radius;
  for (int j = 0; j < n_lat; ++j) {
    const double y = -0.5 * width + width * j / (n_lat - 1);
    double r = radius;
    if (std::abs(y) > flat) {
      const double e = std::abs(y) - flat;
      r = radius - shoulder_radius + std::sqrt(std::max(0.0, shoulder_radius * shoulder_radius - e * e));
    }
    g.lat_y.push_back(y);
    g.lat_r.push_back(r);
  }
  for (int c = 0; c < n_circ; ++c) {
    const double phi = 2.0 * M_PI * c / n_circ;
    for (int j = 0; j < n_lat; ++j)
      g.mesh.vertices.emplace_back(g.lat_r[j] * std::cos(phi), g.lat_y[j], g.lat_r[j] * std::sin(phi));
  }
  for (int c = 0; c < n_circ; ++c) {
    const int c1 = (c + 1) % n_circ;
    for (int j = 0; j + 1 < n_lat; ++j) {
      const int v00 = c * n_lat + j, v01 = c * n_lat + j + 1, v10 = c1 * n_lat + j, v11 = c1 * n_lat + j + 1;
      g.mesh.faces.push_back({v00, v01, v10});
      g.mesh.faces.push_back({v01, v11, v10});
    }
  }
  return g;
}

}  // namespace dem_mobility::core
