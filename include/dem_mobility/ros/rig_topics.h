// The topics of a soil rig of one kind beside the ones every rig has (particles, walls, clock): the
// cone penetrometer's CI samples and its ConeIndexResult. One implementation per rig kind; the rig
// nodelet picks it by the scene's kind. Message conversion only.
#pragma once

#include <memory>
#include <string>

#include <ros/ros.h>

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
  /// Publishes what the rig measured since the last call.
  virtual void PublishProgress(const SoilRig& rig, const std::string& frame) = 0;
  /// The result message (latched): the rig's result, `status` and `error` as in the result file.
  virtual void PublishResult(const SoilRig& rig, const ros::Time& stamp, const std::string& frame,
                             double wall_time) = 0;
  /// The result message of a rig that could not start.
  virtual void PublishSetupError(const std::string& error) = 0;
};

/// The topics of rig scenes of `kind`; ConfigError for a kind without any.
std::unique_ptr<RigTopics> MakeRigTopics(const std::string& kind);

}  // namespace dem_mobility
