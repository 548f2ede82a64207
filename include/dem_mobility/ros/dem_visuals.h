// What users see of the DEM soil in rviz and in the bag: the particles as a PointCloud2 (x, y, z
// and the plastic strain to colour them by) and the rigid walls (container, lid, cone, later the
// tires) as triangle-list markers at their current poses.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>

#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

/// Every live particle (or those `keep` accepts, e.g. one side of a cross-section): float32
/// fields x, y, z and plastic_strain (delta_p / d), in ID order.
void ToPointCloud(const DemSystem& s, sensor_msgs::PointCloud2* cloud,
                  const std::function<bool(const Eigen::Vector3d&)>& keep = nullptr);

/// Every live particle with float32 fields x, y, z, plastic_strain (delta_p / d) and
/// plastic_strain_change: the change of its plastic strain since it was first shown, which
/// `first_shown` (indexed by ID, grown as needed, NaN: not shown yet) keeps from call to call. On a
/// soil under a vehicle the compaction under the wheels shows as a gain, where the prepared bed's
/// own strain (its consolidation, spread over a range) would hide it; the strain also relaxes
/// (eq. 16), so the change has either sign. A re-emitted particle has a new ID: it starts from the
/// state it was laid down with. In ID order.
void ToPointCloud(const DemSystem& s, std::vector<float>* first_shown, sensor_msgs::PointCloud2* cloud);

/// A point message.
geometry_msgs::Point MakePoint(double x, double y, double z);

/// An empty marker of namespace `ns` and `type` (visualization_msgs::Marker::LINE_LIST, ...) in
/// colour (r, g, b, a), at the identity pose, unit scale, action ADD; the frame is left to the caller.
visualization_msgs::Marker ColouredMarker(const std::string& ns, int type, float r, float g, float b, float a);

/// One wall as a TRIANGLE_LIST marker in its body frame, posed at the wall's pose.
visualization_msgs::Marker WallMarker(const DemWall& w, const std::string& ns, int id, float r, float g, float b,
                                      float a);

}  // namespace dem_mobility
