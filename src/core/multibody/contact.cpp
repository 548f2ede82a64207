#include "dem_mobility/core/multibody/contact.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dem_mobility/core/common/asperity_friction.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

using Eigen::Vector3d;

ContactParams ContactParams::Read(const YamlReader& y) {
  ContactParams p;
  p.k_n = y.Positive("k_n");
  p.c_n = y.NonNegative("c_n");
  p.s_n = y.DoubleIn("s_n", 0.0, 1.0);
  p.mu = y.NonNegative("mu");
  p.k_t = y.Positive("k_t");
  p.c_t_anchor = y.NonNegative("c_t_anchor", 0.0);
  p.v_slip = y.Positive("v_slip", 0.01);
  p.c_visc = y.NonNegative("c_visc", 0.0);
  p.c_rr = y.DoubleIn("c_rr", 0.0, 0.5, 0.0);
  return p;
}

Vector3d ContactForce(const ContactParams& p, const Vector3d& point, const Vector3d& n, double depth,
                      const Vector3d& v, long step, ContactHistory* h, double* normal_force) {
  // normal: repulsion k d plus damping, reduced by s_n while separating (eq. 11-12)
  const double vn = n.dot(v);
  const double d_dot = -vn;  // penetration rate
  const double f_rep = p.k_n * depth;
  const double f_damp = d_dot >= 0.0 ? p.c_n * d_dot : p.s_n * p.c_n * d_dot;
  const double fn = std::max(0.0, f_rep + f_damp);
  *normal_force = fn;

  // tangential: the asperity friction element, its anchor a point on the surface
  const Vector3d surface = point + depth * n;
  if (h->last_step != step - 1 && h->last_step != step) h->anchor = surface;
  h->last_step = step;
  const Vector3d vt = v - vn * n;
  Vector3d delta = surface - h->anchor;
  delta -= delta.dot(n) * n;
  const AsperityFriction friction(p.mu, p.k_t, p.v_slip, p.c_t_anchor, p.c_visc);
  bool slipped = false;
  const Vector3d f_t = friction.Force<true>(vt, f_rep, &delta, &slipped);
  if (slipped) {  // the anchor slid on the surface
    h->anchor = surface - delta;
    h->anchor -= (h->anchor - surface).dot(n) * n;
  }
  return fn * n + f_t;
}

// ---------------------------------------------------------------------------------------------
namespace {
void Accumulate(ContactSummary* s, const Vector3d& f, const Vector3d& r, double fn, double depth) {
  s->force += f;
  s->torque += r.cross(f);
  s->normal_force += fn;
  s->max_depth = std::max(s->max_depth, depth);
  ++s->num_contacts;
}
double ContactPointEnergy(const ContactParams& p, const TerrainMesh& t, const Vector3d& x,
                          const ContactHistory& h, long step) {
  TerrainMesh::Hit hit;
  if (!t.Query(x, &hit)) return 0.0;
  double e = 0.5 * p.k_n * hit.depth * hit.depth;
  if (h.last_step == step) {
    Vector3d delta = x + hit.depth * hit.normal - h.anchor;
    delta -= delta.dot(hit.normal) * hit.normal;
    e += 0.5 * p.k_t * delta.squaredNorm();
  }
  return e;
}
}  // namespace

void PointSetContact::Apply(Bodies& bodies, long step) {
  RigidBody& B = bodies[body];
  if (history.size() != points.size()) history.resize(points.size());
  last = ContactSummary();
  applied_step = step;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vector3d r = B.R * points[i];
    const Vector3d x = B.x + r;
    TerrainMesh::Hit hit;
    if (!terrain->Query(x, &hit)) continue;
    double fn;
    const Vector3d f = ContactForce(params, x, hit.normal, hit.depth, B.VelocityAt(r), step, &history[i], &fn);
    B.AddForceAt(f, r);
    Accumulate(&last, f, r, fn, hit.depth);
  }
}
double PointSetContact::PotentialEnergy(const Bodies& bodies) const {
  double e = 0.0;
  const RigidBody& B = bodies[body];
  for (size_t i = 0; i < points.size() && i < history.size(); ++i)
    e += ContactPointEnergy(params, *terrain, B.PointWorld(points[i]), history[i], applied_step);
  return e;
}
StiffnessInfo PointSetContact::Stiffness(const Bodies& bodies) const {
  // all points in contact at once: sum of the rank-one stiffnesses bounds the largest eigenvalue
  const RigidBody& B = bodies[body];
  double w2 = 0.0;
  const double k = std::max(params.k_n, params.k_t);
  for (const auto& p : points) w2 += k * InverseEffectiveMass(B, B.R * p);
  StiffnessInfo s;
  if (w2 <= 0) return s;
  s.omega = std::sqrt(w2);
  const double m_eff = points.size() * k / w2;
  s.zeta = params.c_n / (2.0 * std::sqrt(k * m_eff));
  s.detail = detail::Concat(points.size(), " points of k = ", k, " N/m on body '", B.name, "' ", B.mass, " kg");
  return s;
}

namespace {
Vector3d Vertex(const TireGeometry& t, int col, int j) {
  return t.Vertex(((col % t.n_circ) + t.n_circ) % t.n_circ, j);
}
}  // namespace

void TireContact::Apply(Bodies& bodies, long step) {
  RigidBody& B = bodies[body];
  const TireGeometry& T = *tire;
  if (history.size() != T.mesh.vertices.size()) history.resize(T.mesh.vertices.size());
  last = ContactSummary();
  const Vector3d u = B.R.col(0), a = B.R.col(1), w = B.R.col(2);
  const double reach = T.radius + 0.5 * T.width;
  const double zmax = terrain->MaxHeight(B.x.head<2>().array() - reach, B.x.head<2>().array() + reach);
  if (!std::isfinite(zmax)) return;
  // vertex z = x_z - r rho cos(phi - phi_down) + y a_z: only the columns that can reach zmax
  const double rho = std::hypot(u.z(), w.z());
  int c_lo = 0, c_hi = T.n_circ - 1;
  if (rho > 1e-9) {
    const double q = (B.x.z() - 0.5 * T.width * std::abs(a.z()) - zmax) / (T.radius * rho);
    if (q > 1.0) return;
    if (q > -1.0) {
      const double phi_down = std::atan2(-w.z(), -u.z());
      const double half = std::acos(q);
      const double dphi = 2.0 * M_PI / T.n_circ;
      c_lo = static_cast<int>(std::floor((phi_down - half) / dphi));
      c_hi = static_cast<int>(std::ceil((phi_down + half) / dphi));
      if (c_hi - c_lo >= T.n_circ) {
        c_lo = 0;
        c_hi = T.n_circ - 1;
      }
    }
  }
  // fast path: the tested columns lie over cells tiled by one plane (flat road)
  Vector3d plane_n;
  double plane_off = 0.0;
  bool planar = false;
  if (c_hi - c_lo + 1 < T.n_circ / 4) {
    const Vector3d p0 = B.x + B.R * Vertex(T, c_lo, 0), p1 = B.x + B.R * Vertex(T, c_hi, 0);
    const Eigen::Vector2d ext = (0.5 * T.width * a).head<2>().cwiseAbs() +
                                Eigen::Vector2d::Constant(4.0 * M_PI * T.radius / T.n_circ);
    planar = terrain->BoxPlane(p0.head<2>().cwiseMin(p1.head<2>()) - ext, p0.head<2>().cwiseMax(p1.head<2>()) + ext,
                               &plane_n, &plane_off);
  }
  for (int cc = c_lo; cc <= c_hi; ++cc) {
    const int c = ((cc % T.n_circ) + T.n_circ) % T.n_circ;
    for (int j = 0; j < T.n_lat; ++j) {
      const int vi = c * T.n_lat + j;
      const Vector3d r = B.R * T.mesh.vertices[vi];
      const Vector3d x = B.x + r;
      TerrainMesh::Hit hit;
      if (planar) {
        hit.depth = plane_off - plane_n.dot(x);
        if (hit.depth <= 0.0 || hit.depth > terrain->max_depth()) continue;
        hit.normal = plane_n;
      } else if (!terrain->Query(x, &hit)) {
        continue;
      }
      double fn;
      const Vector3d f = ContactForce(params, x, hit.normal, hit.depth, B.VelocityAt(r), step, &history[vi], &fn);
      B.AddForceAt(f, r);
      Accumulate(&last, f, r, fn, hit.depth);
    }
  }
  // rolling resistance: a moment c_rr R F_n opposing the spin, regularised near zero spin
  if (params.c_rr > 0.0 && last.normal_force > 0.0) {
    const double spin = B.w_world.dot(a);
    const double w_eps = params.v_slip / T.radius;
    const double m = -params.c_rr * T.radius * last.normal_force * std::clamp(spin / w_eps, -1.0, 1.0);
    B.torque += m * a;
    last.torque += m * a;
  }
}
int TireContact::SimultaneousVertices() const {
  // vertices that can be in contact at once: the columns within the terrain's max_depth
  const double half = std::acos(std::max(-1.0, 1.0 - terrain->max_depth() / tire->radius));
  const int cols = 1 + 2 * static_cast<int>(std::ceil(half / (2.0 * M_PI / tire->n_circ)));
  return std::min(tire->n_circ, cols) * tire->n_lat;
}

}  // namespace dem_mobility::core
