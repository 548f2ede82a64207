#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/common/input_files.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

namespace {

// a ring of `n` vertices of radius r at lateral offset y (body frame: spin axis y)
void AddRing(TriMesh* m, double r, double y, int n) {
  for (int c = 0; c < n; ++c) {
    const double phi = 2.0 * M_PI * c / n;
    m->vertices.emplace_back(r * std::cos(phi), y, r * std::sin(phi));
  }
}

// quads between ring a and ring b (n vertices each), wound so that their normal points along `out`
void JoinRings(TriMesh* m, int a, int b, int n, bool flip) {
  for (int c = 0; c < n; ++c) {
    const int c1 = (c + 1) % n;
    const int a0 = a + c, a1 = a + c1, b0 = b + c, b1 = b + c1;
    if (flip) {
      m->faces.push_back({a0, b1, b0});
      m->faces.push_back({a0, a1, b1});
    } else {
      m->faces.push_back({a0, b0, b1});
      m->faces.push_back({a0, b1, a1});
    }
  }
}

}  // namespace

TireGeometry TireGeometry::Make(double radius, double width, double shoulder_radius, int n_circ, int n_lat,
                                const TireLugs& lugs, double rim_radius, int sidewall_rings) {
  DM_THROW_UNLESS(radius > 0 && width > 0, "tire: radius and width must be positive");
  DM_THROW_UNLESS(shoulder_radius >= 0 && 2 * shoulder_radius <= width && shoulder_radius < radius,
                  "tire: shoulder_radius must be in [0, width/2]");
  DM_THROW_UNLESS(n_circ >= 8 && n_lat >= 2, "tire: need n_circ >= 8 and n_lat >= 2");
  DM_THROW_UNLESS(lugs.count >= 0 && lugs.height >= 0.0 && lugs.height < 0.5 * radius && lugs.fraction > 0.0 &&
                      lugs.fraction < 1.0,
                  "tire: lugs need count >= 0, 0 <= height < radius / 2 and 0 < fraction < 1");
  DM_THROW_UNLESS(lugs.count == 0 || n_circ >= 4 * lugs.count, "tire: ", lugs.count,
                  " lugs need n_circ >= 4 x lugs (", 4 * lugs.count, ")");
  DM_THROW_UNLESS(sidewall_rings >= 1, "tire: sidewall_rings must be >= 1");
  TireGeometry g;
  g.radius = radius;
  g.width = width;
  g.shoulder_radius = shoulder_radius;
  g.n_circ = n_circ;
  g.n_lat = n_lat;
  g.lugs = lugs;
  g.sidewall_rings = sidewall_rings;
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
  // a column between lugs lies on the carcass, `height` below the lugs' tops
  const double carcass = radius - lugs.height;
  for (int c = 0; c < n_circ; ++c) {
    const double phi = 2.0 * M_PI * c / n_circ;
    const double pitch = lugs.count > 0 ? std::fmod(static_cast<double>(c) * lugs.count / n_circ, 1.0) : 0.0;
    const bool lug = lugs.count == 0 || pitch < lugs.fraction;
    for (int j = 0; j < n_lat; ++j) {
      const double r = lug ? g.lat_r[j] : std::min(g.lat_r[j], carcass);
      g.mesh.vertices.emplace_back(r * std::cos(phi), g.lat_y[j], r * std::sin(phi));
    }
  }
  for (int c = 0; c < n_circ; ++c) {
    const int c1 = (c + 1) % n_circ;
    for (int j = 0; j + 1 < n_lat; ++j) {
      const int v00 = c * n_lat + j, v01 = c * n_lat + j + 1, v10 = c1 * n_lat + j, v11 = c1 * n_lat + j + 1;
      g.mesh.faces.push_back({v00, v01, v10});
      g.mesh.faces.push_back({v01, v11, v10});
    }
  }
  // the soil's surface: the tread closed by two flat sidewalls (annuli from the tread's edge ring
  // down to the rim), so that no particle gets inside the tire from the side
  const double edge = std::min(g.lat_r.front(), carcass);
  g.rim_radius = rim_radius > 0.0 ? rim_radius : 0.45 * radius;
  DM_THROW_UNLESS(g.rim_radius < edge, "tire: rim_radius ", g.rim_radius, " m must be below the tread's edge (",
                  edge, " m)");
  g.soil_mesh = g.mesh;
  TriMesh& m = g.soil_mesh;
  for (int side = 0; side < 2; ++side) {
    const int j = side == 0 ? 0 : n_lat - 1;
    const double y = g.lat_y[j];
    int prev = -1;  // first ring: the tread's edge vertices, one per column (stride n_lat)
    for (int k = 1; k <= sidewall_rings; ++k) {
      const double r = edge - (edge - g.rim_radius) * k / sidewall_rings;
      const int ring = static_cast<int>(m.vertices.size());
      AddRing(&m, r, y, n_circ);
      if (prev < 0) {
        for (int c = 0; c < n_circ; ++c) {
          const int c1 = (c + 1) % n_circ;
          const int a0 = c * n_lat + j, a1 = c1 * n_lat + j, b0 = ring + c, b1 = ring + c1;
          // outward normal: -y on the left side (j = 0), +y on the right
          if (side == 0) {
            m.faces.push_back({a0, b0, b1});
            m.faces.push_back({a0, b1, a1});
          } else {
            m.faces.push_back({a0, b1, b0});
            m.faces.push_back({a0, a1, b1});
          }
        }
      } else {
        JoinRings(&m, prev, ring, n_circ, side == 1);
      }
      prev = ring;
    }
  }
  return g;
}

TireGeometry TireGeometry::Read(const YamlReader& y) {
  TireLugs lugs;
  if (y.Has("lugs")) {
    const YamlReader l = y.Child("lugs");
    lugs.count = l.Int("count");
    if (lugs.count < 0 || lugs.count > 200) l.Fail("count", "must lie in [0, 200]");
    lugs.height = l.NonNegative("height");
    lugs.fraction = l.DoubleIn("fraction", 0.05, 0.95, 0.5);
    l.Finish();
  }
  const double radius = y.Positive("radius"), width = y.Positive("width");
  const double shoulder = y.NonNegative("shoulder_radius");
  const int n_circ = y.Int("n_circ"), n_lat = y.Int("n_lat");
  if (n_circ < 8 || n_circ > 4096) y.Fail("n_circ", "must lie in [8, 4096]");
  if (n_lat < 2 || n_lat > 512) y.Fail("n_lat", "must lie in [2, 512]");
  if (2 * shoulder > width) y.Fail("shoulder_radius", "must be at most half the width");
  if (lugs.height >= 0.5 * radius) y.Fail("lugs.height", "must be below half the radius");
  if (lugs.count > 0 && n_circ < 4 * lugs.count) y.Fail("n_circ", "must be at least 4 x lugs.count");
  const double rim = y.DoubleIn("rim_radius", 0.0, radius, 0.0);
  const int rings = y.Int("sidewall_rings", 4);
  if (rings < 1 || rings > 64) y.Fail("sidewall_rings", "must lie in [1, 64]");
  TireGeometry t;
  try {
    t = Make(radius, width, shoulder, n_circ, n_lat, lugs, rim, rings);
  } catch (const ConfigError& e) {
    y.Fail("rim_radius", e.what());
  }
  if (y.Has("soil_mesh")) {
    t.mesh_file = y.ResolvePath(y.String("soil_mesh"));
    t.soil_mesh = LoadObjMesh(t.mesh_file);
    double rmax = 0.0;
    for (const Eigen::Vector3d& v : t.soil_mesh.vertices) rmax = std::max(rmax, std::hypot(v.x(), v.z()));
    if (rmax > 1.5 * radius)
      y.Fail("soil_mesh", "reaches " + detail::Concat(rmax) + " m from the spin axis (body y), beyond 1.5 x radius");
  }
  y.Finish();
  return t;
}

TriMesh LoadObjMesh(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open the mesh file");
  NoteInputFile(path);  // (what a checkpoint records of the run: common/input_files.h)
  TriMesh m;
  std::string line;
  int no = 0;
  while (std::getline(in, line)) {
    ++no;
    std::istringstream ss(line);
    std::string tag;
    if (!(ss >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Eigen::Vector3d v;
      if (!(ss >> v.x() >> v.y() >> v.z()) || !v.allFinite())
        throw ConfigError(detail::Concat(path, ":", no, ": a vertex needs three finite numbers"));
      m.vertices.push_back(v);
    } else if (tag == "f") {
      std::vector<int> idx;
      std::string tok;
      while (ss >> tok) {
        int k = 0;
        try {
          k = std::stoi(tok.substr(0, tok.find('/')));
        } catch (...) {
          throw ConfigError(detail::Concat(path, ":", no, ": bad face index '", tok, "'"));
        }
        k = k < 0 ? static_cast<int>(m.vertices.size()) + k : k - 1;
        if (k < 0 || k >= static_cast<int>(m.vertices.size()))
          throw ConfigError(detail::Concat(path, ":", no, ": face index '", tok, "' names no vertex"));
        idx.push_back(k);
      }
      if (idx.size() < 3) throw ConfigError(detail::Concat(path, ":", no, ": a face needs 3 vertices"));
      for (size_t k = 1; k + 1 < idx.size(); ++k) m.faces.push_back({idx[0], idx[k], idx[k + 1]});
    }
  }
  if (m.faces.empty()) throw ConfigError(path + ": no faces (f lines) in the mesh file");
  return m;
}

}  // namespace dem_mobility::core
