#include "dem_mobility/ros/rig_topics.h"

#include "dem_mobility/ConeIndexResult.h"
#include "dem_mobility/ConePenetration.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {
namespace {

class ConeTopics final : public RigTopics {
 public:
  void Advertise(ros::NodeHandle& nh) override {
    penetration_ = nh.advertise<ConePenetration>("cone/penetration", 100);
    result_ = nh.advertise<ConeIndexResult>("result", 1, true);
  }
  bool Subscribed() const override {
    return penetration_.getNumSubscribers() > 0 && result_.getNumSubscribers() > 0;
  }
  void PublishProgress(const SoilRig& rig, const std::string& frame) override {
    const auto& cone = static_cast<const ConePenetrometer&>(rig);
    for (; published_ < cone.samples().size(); ++published_) {
      const ConeSample& c = cone.samples()[published_];
      auto m = boost::make_shared<ConePenetration>();
      m->header.stamp = ros::Time(cone.dem().time());  // published as soon as the sample is complete
      m->header.frame_id = frame;
      m->phase = cone.phase();
      m->tip_depth = c.depth;
      m->speed = c.speed;
      m->force = c.force;
      m->cone_index_psi = c.ci_psi;
      penetration_.publish(m);
    }
  }
  void PublishResult(const SoilRig& rig, const ros::Time& stamp, const std::string& frame, double wall_time) override {
    const auto& cone = static_cast<const ConePenetrometer&>(rig);
    const ConeResult r = cone.Result();
    const ResultFile f = ConeResultFile(r, cone.params());
    ConeIndexResult m;
    m.header.stamp = stamp;
    m.header.frame_id = frame;
    m.scene = cone.params().file;
    m.fidelity = r.level;
    m.cohesion_factor = r.cohesion_factor;
    m.friction = r.friction;
    m.cone_index_psi = r.ci_psi;
    m.cone_index_std_psi = r.ci_std_psi;
    m.cone_speed_min = r.speed_min;
    m.cone_speed_max = r.speed_max;
    m.particles = r.particles;
    m.bulk_density = r.density_consolidated;
    m.simulated_time = r.sim_time;
    m.wall_time = wall_time;
    m.status = f.status();
    m.error = f.error();
    result_.publish(m);
  }
  void PublishSetupError(const std::string& error) override {
    ConeIndexResult m;
    m.header.stamp = ros::Time(1e-6);
    m.status = "error";
    m.error = error;
    result_.publish(m);
  }
 private:
  ros::Publisher penetration_, result_;
  size_t published_ = 0;
};

}  // namespace

std::unique_ptr<RigTopics> MakeRigTopics(const std::string& kind) {
  if (kind == "cone_penetrometer") return std::make_unique<ConeTopics>();
  throw ConfigError("the rig nodelet has no topics for scenes of kind '" + kind + "'");
}

}  // namespace dem_mobility
