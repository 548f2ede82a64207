// Penalty contact with asperity friction (paper eq. 8-14) against analytic friction limits.
#include <gtest/gtest.h>

#include <cmath>

#include "dem_mobility/core/common/rotation.h"
#include "test_util.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

// A 10 kg box (0.4 x 0.4 x 0.2 m, contact points at its 8 corners) resting on a triangle-mesh
// plane tilted by theta about y (rising toward +x); gravity straight down.
struct BoxOnIncline {
  MultibodySystem s;
  std::unique_ptr<TerrainMesh> terrain;
  int box;
  Vector3d down_slope;
  BoxOnIncline(double theta_deg, double mu) {
    const double th = theta_deg * M_PI / 180.0;
    const Eigen::Matrix3d tilt = RotY(-th);
    TriMesh plane = MakeFlatRoad(-5.0, 10.0, 4.0, 0.5);
    for (auto& v : plane.vertices) v = tilt * v;
    terrain = std::make_unique<TerrainMesh>(plane, 0.5, 0.05);
    const Vector3d n = tilt * Vector3d::UnitZ();
    down_slope = -(tilt * Vector3d::UnitX());
    RigidBody b = test::MakeBody("box", 10.0, Vector3d(10.0 * (0.04 + 0.16) / 12, 10.0 * (0.04 + 0.16) / 12, 10.0 * 0.32 / 12));
    b.R = tilt;
    b.x = 0.1 * n;  // bottom face on the plane
    box = s.AddBody(b);
    PointSetContact c;
    c.name = "box_corners";
    c.body = box;
    for (double x : {-0.2, 0.2})
      for (double y : {-0.2, 0.2})
        for (double z : {-0.1, 0.1}) c.points.emplace_back(x, y, z);
    c.params.k_n = 1e6;
    c.params.c_n = 300;
    c.params.s_n = 0.5;
    c.params.mu = mu;
    c.params.k_t = 1e6;
    c.params.c_t_anchor = 300;
    c.params.v_slip = 1e-3;
    c.terrain = terrain.get();
    s.point_contacts.push_back(c);
    s.Finalize(5e-5);
  }
  double Along() const { return s.body(box).x.dot(down_slope); }
};

TEST(Contact, BoxSticksBelowTheFrictionAngle) {
  const double mu = 0.5;  // friction angle 26.6 deg
  BoxOnIncline b(22.0, mu);
  while (b.s.time() < 0.5) b.s.Step();
  const double x0 = b.Along();
  while (b.s.time() < 3.0) b.s.Step();
  // no creep: the anchor springs hold it (a regularised Coulomb law alone would creep)
  EXPECT_LT(std::abs(b.Along() - x0), 1e-6);
  EXPECT_LT(b.s.body(b.box).v.norm(), 1e-5);
  // contact force balances the weight
  EXPECT_NEAR(b.s.point_contacts[0].last.force.z(), 10.0 * 9.81, 1e-3 * 98.1);
}

TEST(Contact, BoxSlidesAboveTheFrictionAngleWithCoulombAcceleration) {
  const double mu = 0.5, th = 35.0 * M_PI / 180.0;
  BoxOnIncline b(35.0, mu);
  while (b.s.time() < 0.5) b.s.Step();
  const double v0 = b.s.body(b.box).v.dot(b.down_slope), t0 = b.s.time();
  while (b.s.time() < 1.5) b.s.Step();
  const double a = (b.s.body(b.box).v.dot(b.down_slope) - v0) / (b.s.time() - t0);
  const double expected = 9.81 * (std::sin(th) - mu * std::cos(th));
  EXPECT_NEAR(a, expected, 0.01 * expected);
}

TEST(Contact, RestingNormalForceIsKTimesDepth) {
  // a single contact point under a 1 kg body at rest: depth = m g / k_n
  TerrainMesh t(MakeFlatRoad(-1, 2, 2, 0.5), 0.5, 0.05);
  MultibodySystem s;
  const int b = s.AddBody(test::MakeBody("ball", 1.0, Vector3d(0.01, 0.01, 0.01), Vector3d(0, 0, 0.05)));
  PointSetContact c;
  c.name = "point";
  c.body = b;
  c.points = {Vector3d(0, 0, -0.05)};
  c.params.k_n = 1e5;
  c.params.c_n = 200;
  c.params.s_n = 1.0;
  c.params.mu = 0.5;
  c.params.k_t = 1e5;
  c.params.v_slip = 1e-3;
  c.terrain = &t;
  s.point_contacts.push_back(c);
  s.Finalize(1e-4);
  for (int i = 0; i < 20000; ++i) s.Step();
  EXPECT_NEAR(s.point_contacts[0].last.max_depth, 9.81 / 1e5, 1e-3 * 9.81 / 1e5);
}

TEST(Contact, SeparationFactorReducesDampingWhileSeparating) {
  ContactParams p;
  p.k_n = 1e5;
  p.c_n = 100;
  p.s_n = 0.25;
  p.mu = 0.0;
  p.k_t = 1e5;
  p.v_slip = 1e-3;
  ContactHistory h;
  double fn;
  const Vector3d n = Vector3d::UnitZ();
  // approaching at 0.1 m/s: k d + c v; separating: k d - s_n c v
  ContactForce(p, Vector3d::Zero(), n, 1e-3, Vector3d(0, 0, -0.1), 0, &h, &fn);
  EXPECT_NEAR(fn, 1e5 * 1e-3 + 100 * 0.1, 1e-9);
  ContactForce(p, Vector3d::Zero(), n, 1e-3, Vector3d(0, 0, 0.1), 1, &h, &fn);
  EXPECT_NEAR(fn, 1e5 * 1e-3 - 0.25 * 100 * 0.1, 1e-9);
}

TEST(Contact, TerrainGridQueriesOnlyTheCell) {
  TerrainMesh t(MakeFlatRoad(0, 100, 10, 1.0), 1.0, 0.05);
  TerrainMesh::Hit hit;
  EXPECT_TRUE(t.Query(Vector3d(50.3, 1.2, -0.01), &hit));
  EXPECT_NEAR(hit.depth, 0.01, 1e-12);
  EXPECT_FALSE(t.Query(Vector3d(50.3, 1.2, 0.01), &hit));    // above
  EXPECT_FALSE(t.Query(Vector3d(50.3, 1.2, -0.06), &hit));   // deeper than max_depth: behind
  EXPECT_FALSE(t.Query(Vector3d(150.0, 1.2, -0.01), &hit));  // off the mesh
  Vector3d n;
  double off;
  EXPECT_TRUE(t.BoxPlane(Eigen::Vector2d(10.2, -1.5), Eigen::Vector2d(11.7, 0.5), &n, &off));
  EXPECT_NEAR(n.z(), 1.0, 1e-12);
}

}  // namespace
}  // namespace dem_mobility::core
