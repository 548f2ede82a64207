#include "dem_mobility/ros/vehicle_visuals.h"
#include "dem_mobility/ros/core_names.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dem_mobility {
namespace {

geometry_msgs::Point P(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

geometry_msgs::Transform T(const Eigen::Vector3d& x, const Eigen::Quaterniond& q) {
  geometry_msgs::Transform t;
  t.translation.x = x.x();
  t.translation.y = x.y();
  t.translation.z = x.z();
  t.rotation.w = q.w();
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  return t;
}

geometry_msgs::Quaternion Q(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}

std_msgs::ColorRGBA Color(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::Marker Base(const std::string& frame, const ros::Time& stamp, const std::string& ns, int id,
                                int type) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

bool StartsWith(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

}  // namespace

geometry_msgs::TransformStamped SlopeTransform(const Eigen::Vector3d& gravity, const ros::Time& stamp,
                                               const std::string& map, const std::string& world) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = map;
  t.child_frame_id = world;
  // the slope frame's "up" (against gravity) onto map's z by the least rotation: for a grade alone
  // a rotation of -grade about y (world x, uphill, rises in map), a side slope adds the roll
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(-gravity.normalized(), Eigen::Vector3d::UnitZ());
  t.transform = T(Eigen::Vector3d::Zero(), q);
  return t;
}

tf2_msgs::TFMessage BodyTransforms(const Vehicle& v, const ros::Time& stamp, const std::string& world,
                                   const std::string& base) {
  const MultibodySystem& sys = v.system();
  const RigidBody& c = sys.body(v.chassis());
  const Eigen::Vector3d xf = v.ChassisFramePosition();
  tf2_msgs::TFMessage m;
  m.transforms.reserve(sys.num_bodies() - 1);
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = world;
  t.child_frame_id = base;
  t.transform = T(xf, Eigen::Quaterniond(c.R));
  m.transforms.push_back(t);
  t.header.frame_id = base;
  for (int i = 1; i < sys.num_bodies(); ++i) {
    if (i == v.chassis()) continue;
    const RigidBody& b = sys.body(i);
    t.child_frame_id = b.name;
    t.transform = T(c.R.transpose() * (b.x - xf), Eigen::Quaterniond(c.R.transpose() * b.R));
    m.transforms.push_back(t);
  }
  return m;
}

nav_msgs::Odometry ChassisOdometry(const Vehicle& v, const ros::Time& stamp, const std::string& world,
                                   const std::string& base) {
  const RigidBody& c = v.system().body(v.chassis());
  const Eigen::Vector3d xf = v.ChassisFramePosition();
  nav_msgs::Odometry o;
  o.header.stamp = stamp;
  o.header.frame_id = world;
  o.child_frame_id = base;
  o.pose.pose.position = P(xf);
  o.pose.pose.orientation = Q(Eigen::Quaterniond(c.R));
  const Eigen::Vector3d w_world = c.R * c.w;
  const Eigen::Vector3d v_base = c.R.transpose() * (c.v + w_world.cross(xf - c.x));
  o.twist.twist.linear.x = v_base.x();
  o.twist.twist.linear.y = v_base.y();
  o.twist.twist.linear.z = v_base.z();
  o.twist.twist.angular.x = c.w.x();
  o.twist.twist.angular.y = c.w.y();
  o.twist.twist.angular.z = c.w.z();
  return o;
}

visualization_msgs::MarkerArray BodyMarkers(const Vehicle& v, const ros::Time& stamp, const std::string& base) {
  const MultibodySystem& sys = v.system();
  const RigidBody& c = sys.body(v.chassis());
  const Eigen::Vector3d xf = v.ChassisFramePosition();
  visualization_msgs::MarkerArray arr;
  // chassis: a translucent box over the wheels, so the suspension stays visible
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d w = c.R.transpose() * (sys.body(v.wheel(i)).x - xf);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  const double r = v.tire().radius, width = v.tire().width;
  auto box = Base(base, stamp, "chassis", 0, visualization_msgs::Marker::CUBE);
  box.frame_locked = true;
  box.pose.position = P(Eigen::Vector3d(0.5 * (lo.x() + hi.x()), 0.0, hi.z() + 0.55 * r + 0.35));
  box.scale.x = hi.x() - lo.x() + 2.2 * r;
  box.scale.y = hi.y() - lo.y() + width;
  box.scale.z = 0.7;
  box.color = Color(0.45f, 0.52f, 0.30f, 0.55f);  // olive drab
  arr.markers.push_back(box);
  int id = 0;
  for (int i = 1; i < sys.num_bodies(); ++i) {
    if (i == v.chassis()) continue;
    const RigidBody& b = sys.body(i);
    const bool wheel = StartsWith(b.name, "wheel_");
    auto m = Base(b.name, stamp, wheel ? "wheels" : "bodies", id++,
                  wheel ? visualization_msgs::Marker::CYLINDER : visualization_msgs::Marker::SPHERE);
    m.frame_locked = true;
    if (wheel) {  // rviz cylinders run along z; the wheel spins about its y axis
      m.pose.orientation = Q(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())));
      m.scale.x = m.scale.y = 2.0 * r;
      m.scale.z = width;
      m.color = Color(0.12f, 0.12f, 0.12f);
    } else {
      // a steel-density sphere of the body's mass, so heavy parts look heavy
      const double d = std::clamp(2.0 * std::cbrt(3.0 * b.mass / (4.0 * M_PI * 7800.0)), 0.06, 0.35);
      m.scale.x = m.scale.y = m.scale.z = d;
      if (StartsWith(b.name, "uca_") || StartsWith(b.name, "lca_")) m.color = Color(0.85f, 0.55f, 0.1f);
      else if (StartsWith(b.name, "upright_")) m.color = Color(0.2f, 0.45f, 0.85f);
      else m.color = Color(0.75f, 0.75f, 0.78f);  // driveline, steering
    }
    arr.markers.push_back(m);
  }
  return arr;
}

visualization_msgs::MarkerArray LiveMarkers(const VehicleCoSim& sim, const ros::Time& stamp, const std::string& world,
                                            double force_scale) {
  const Vehicle& v = sim.vehicle();
  const MultibodySystem& sys = v.system();
  visualization_msgs::MarkerArray arr;
  for (int i = 0; i < 4; ++i) {
    auto a = Base(world, stamp, "wheel_forces", i, visualization_msgs::Marker::ARROW);
    const Eigen::Vector3d x = sys.body(v.wheel(i)).x;
    a.points.push_back(P(x));
    a.points.push_back(P(x + force_scale * v.wheel_wrench(i).force));
    a.scale.x = 0.05;  // shaft diameter
    a.scale.y = 0.12;  // head diameter
    a.scale.z = 0.15;  // head length
    a.color = Color(0.9f, 0.1f, 0.1f);
    arr.markers.push_back(a);
  }
  auto joints = Base(world, stamp, "joints", 0, visualization_msgs::Marker::LINE_LIST);
  joints.scale.x = 0.02;
  joints.color = Color(0.95f, 0.95f, 0.2f);
  for (const PointJoint& j : sys.point_joints) {
    for (const auto& [body, r] : {std::make_pair(j.a, j.ra), std::make_pair(j.b, j.rb)}) {
      if (body == 0 || body == v.chassis()) continue;  // the chassis mounts would hide the rest
      const RigidBody& b = sys.body(body);
      joints.points.push_back(P(b.x));
      joints.points.push_back(P(b.PointWorld(r)));
    }
  }
  arr.markers.push_back(joints);
  auto label = Base(world, stamp, "label", 0, visualization_msgs::Marker::TEXT_VIEW_FACING);
  label.pose.position = P(v.ChassisFramePosition() + Eigen::Vector3d(0, 0, 2.6));
  label.scale.z = 0.45;
  label.color = Color(1.0f, 1.0f, 1.0f);
  char text[160];
  std::snprintf(text, sizeof(text), "t = %.2f s   %.2f m/s   grade %.1f deg", std::max(0.0, sim.driver_time()),
                v.ForwardSpeed(), sim.params().grade_deg);
  label.text = text;
  arr.markers.push_back(label);
  return arr;
}

}  // namespace dem_mobility
