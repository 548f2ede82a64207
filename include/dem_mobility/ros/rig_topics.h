// The topics of a soil rig of one kind beside the ones every rig has (particles, walls, clock): the
// cone penetrometer's CI samples and its ConeIndexResult; the single-wheel rig's wheel wrench, its
// samples and its SingleWheelResult. One implementation per rig kind; the rig nodelet picks it by
// the scene's kind, and asks it which particles make the cross-section and what the tools look
// like. Message conversion only.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <ros/ros.h>
#include <visualization_msgs/Marker.h>

#include "dem_mobility/core/scenes/soil_rig.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

class RigTopics {
 public:
  virtual ~RigTopics() = default;
  /// Advertises the rig's own topics in `nh` (the run's namespace).
  virtual void Advertise(ros::NodeHandle& nh) = 0;
  /// True once a recorder subscribes to every one of them.
  virtual bool Subscribed() const = 0;
  /// Publishes what the rig measured since the last call (called after every step).
  virtual void PublishProgress(const SoilRig& rig, const std::string& frame) = 0;
  /// The result message (latched): the rig's result, `status` and `error` as in the result file.
  virtual void PublishResult(const SoilRig& rig, const ros::Time& stamp, const std::string& frame,
                             double wall_time) = 0;
  /// The result message of a rig that could not start.
  virtual void PublishSetupError(const std::string& error) = 0;

  /// The particles of the cross-section cloud (terrain/particles_section) now: by default the
  /// half y >= 0, through the cone's axis.
  virtual std::function<bool(const Eigen::Vector3d&)> Section(const SoilRig& rig) const;
  /// The moving parts of one frame (terrain/tools; the nodelet stamps them, sets the frame and adds
  /// the status text): by default every moving wall at its pose.
  virtual void AddTools(const SoilRig& rig, std::vector<visualization_msgs::Marker>* markers);
  /// The status text (by default the rig's StatusLine()) and where it goes (by default under the
  /// container's floor).
  virtual std::string StatusText(const SoilRig& rig) const { return rig.StatusLine(); }
  virtual Eigen::Vector3d StatusPosition(const SoilRig& rig) const;
};

/// The topics of rig scenes of `kind`; ConfigError for a kind without any.
std::unique_ptr<RigTopics> MakeRigTopics(const std::string& kind);

}  // namespace dem_mobility
