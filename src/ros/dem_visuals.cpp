#include "dem_mobility/ros/dem_visuals.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/ros/core_names.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include <sensor_msgs/point_cloud2_iterator.h>

namespace dem_mobility {

void ToPointCloud(const DemSystem& s, sensor_msgs::PointCloud2* cloud,
                  const std::function<bool(const Eigen::Vector3d&)>& keep) {
  int n = 0;
  for (int id = 0; id < s.size(); ++id)
    if (s.alive(id) && (!keep || keep(s.position(id)))) ++n;
  sensor_msgs::PointCloud2Modifier mod(*cloud);
  mod.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                           "z", 1, sensor_msgs::PointField::FLOAT32, "plastic_strain", 1,
                           sensor_msgs::PointField::FLOAT32);
  mod.resize(n);
  cloud->height = 1;
  cloud->width = n;
  cloud->is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  sensor_msgs::PointCloud2Iterator<float> e(*cloud, "plastic_strain");
  const double inv_d = 1.0 / s.soil().diameter;
  // in ID order, so that a particle keeps its place in the cloud from one message to the next
  for (int id = 0; id < s.size(); ++id) {
    if (!s.alive(id)) continue;
    const Eigen::Vector3d p = s.position(id);
    if (keep && !keep(p)) continue;
    *x = static_cast<float>(p.x());
    *y = static_cast<float>(p.y());
    *z = static_cast<float>(p.z());
    *e = static_cast<float>(s.plastic_deformation(id) * inv_d);
    ++x, ++y, ++z, ++e;
  }
}

void ToPointCloud(const DemSystem& s, std::vector<float>* first_shown, sensor_msgs::PointCloud2* cloud) {
  const int n = s.num_alive();
  sensor_msgs::PointCloud2Modifier mod(*cloud);
  mod.setPointCloud2Fields(5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                           "z", 1, sensor_msgs::PointField::FLOAT32, "plastic_strain", 1,
                           sensor_msgs::PointField::FLOAT32, "plastic_strain_change", 1,
                           sensor_msgs::PointField::FLOAT32);
  mod.resize(n);
  cloud->height = 1;
  cloud->width = n;
  cloud->is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  sensor_msgs::PointCloud2Iterator<float> e(*cloud, "plastic_strain"), de(*cloud, "plastic_strain_change");
  const double inv_d = 1.0 / s.soil().diameter;
  if (static_cast<int>(first_shown->size()) < s.size())
    first_shown->resize(s.size(), std::numeric_limits<float>::quiet_NaN());
  int written = 0;
  for (int id = 0; id < s.size(); ++id) {
    if (!s.alive(id)) continue;
    const Eigen::Vector3d p = s.position(id);
    const float strain = static_cast<float>(s.plastic_deformation(id) * inv_d);
    float& first = (*first_shown)[id];
    if (std::isnan(first)) first = strain;
    *x = static_cast<float>(p.x());
    *y = static_cast<float>(p.y());
    *z = static_cast<float>(p.z());
    *e = strain;
    *de = strain - first;
    ++x, ++y, ++z, ++e, ++de, ++written;
  }
  DM_THROW_UNLESS(written == n, "ToPointCloud: ", written, " live particles for num_alive() = ", n);
}

geometry_msgs::Point MakePoint(double x, double y, double z) {
  geometry_msgs::Point p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}

visualization_msgs::Marker ColouredMarker(const std::string& ns, int type, float r, float g, float b, float a) {
  visualization_msgs::Marker m;
  m.ns = ns;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = a;
  return m;
}

visualization_msgs::Marker WallMarker(const DemWall& w, const std::string& ns, int id, float r, float g, float b,
                                      float a) {
  visualization_msgs::Marker m = ColouredMarker(ns, visualization_msgs::Marker::TRIANGLE_LIST, r, g, b, a);
  m.id = id;
  m.pose.position.x = w.position.x();
  m.pose.position.y = w.position.y();
  m.pose.position.z = w.position.z();
  const Eigen::Quaterniond q(w.rotation);
  m.pose.orientation.x = q.x();
  m.pose.orientation.y = q.y();
  m.pose.orientation.z = q.z();
  m.pose.orientation.w = q.w();
  for (const auto& f : w.mesh.faces)
    for (int k = 0; k < 3; ++k) {
      geometry_msgs::Point p;
      p.x = w.mesh.vertices[f[k]].x();
      p.y = w.mesh.vertices[f[k]].y();
      p.z = w.mesh.vertices[f[k]].z();
      m.points.push_back(p);
    }
  return m;
}

}  // namespace dem_mobility
