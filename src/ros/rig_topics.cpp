#include "dem_mobility/ros/rig_topics.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include <geometry_msgs/WrenchStamped.h>
#include <tf2_msgs/TFMessage.h>

#include "dem_mobility/ConeIndexResult.h"
#include "dem_mobility/ConePenetration.h"
#include "dem_mobility/SingleWheelResult.h"
#include "dem_mobility/WheelRigSample.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/core/scenes/single_wheel.h"
#include "dem_mobility/ros/core_names.h"
#include "dem_mobility/ros/dem_visuals.h"

namespace dem_mobility {

std::function<bool(const Eigen::Vector3d&)> RigTopics::Section(const SoilRig&) const {
  return [](const Eigen::Vector3d& x) { return x.y() >= 0.0; };
}

void RigTopics::AddTools(const SoilRig& rig, std::vector<visualization_msgs::Marker>* markers) {
  static const float kColours[][4] = {{0.85f, 0.3f, 0.1f, 1.0f}, {0.7f, 0.7f, 0.7f, 1.0f}, {0.2f, 0.4f, 0.9f, 0.6f}};
  const DemSystem& s = rig.dem();
  int id = 0;
  for (int w : rig.moving_walls()) {
    const float* c = kColours[std::min(id, 2)];
    markers->push_back(WallMarker(s.wall(w), s.wall(w).name, id++, c[0], c[1], c[2], c[3]));
  }
}

Eigen::Vector3d RigTopics::StatusPosition(const SoilRig&) const { return Eigen::Vector3d(0.0, 0.0, -0.25); }

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
      m->cone_index_psi = c.cone_index_psi;
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
    m.cone_index_psi = r.cone_index_psi;
    m.cone_index_std_psi = r.cone_index_std_psi;
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


void SetPose(const Eigen::Vector3d& x, const Eigen::Quaterniond& q, geometry_msgs::Pose* pose) {
  pose->position.x = x.x();
  pose->position.y = x.y();
  pose->position.z = x.z();
  pose->orientation.x = q.x();
  pose->orientation.y = q.y();
  pose->orientation.z = q.z();
  pose->orientation.w = q.w();
}


/// The single-wheel rig (scenes/single_wheel.h): the soil's wrench on the wheel (wheel/wrench, in
/// the frame `wheel`: at the wheel centre, axes parallel to the scene frame, on /tf), its samples
/// (wheel/sample), its result (SingleWheelResult); the tire, the carriage and the lid as tools; the
/// cross-section through the wheel's mid-plane (the far half of its track).
class WheelTopics final : public RigTopics {
 public:
  void Advertise(ros::NodeHandle& nh) override {
    ros::NodeHandle root;
    tf_ = root.advertise<tf2_msgs::TFMessage>("/tf", 100);
    wrench_ = nh.advertise<geometry_msgs::WrenchStamped>("wheel/wrench", 100);
    sample_ = nh.advertise<WheelRigSample>("wheel/sample", 100);
    result_ = nh.advertise<SingleWheelResult>("result", 1, true);
  }
  bool Subscribed() const override {
    return tf_.getNumSubscribers() > 0 && wrench_.getNumSubscribers() > 0 && sample_.getNumSubscribers() > 0 &&
           result_.getNumSubscribers() > 0;
  }

  void PublishProgress(const SoilRig& rig, const std::string& frame) override {
    const auto& wheel = static_cast<const SingleWheelRig&>(rig);
    if (!wheel.bin().prepared()) return;  // the tire is parked until the soil is ready
    const DemSystem& s = wheel.dem();
    if (wrench_every_ == 0)
      wrench_every_ = std::max(1L, std::lround(wheel.params().sample_interval / s.dt()));
    const ros::Time stamp(s.time());
    if (s.step_count() % wrench_every_ == 0 || wheel.done()) {
      // the wheel frame at the wheel centre, its axes the scene's (the carriage's: it does not spin)
      const WheelState& w = wheel.wheel();
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped t;
      t.header.stamp = stamp;
      t.header.frame_id = frame;
      t.child_frame_id = frame_;
      t.transform.translation.x = w.position.x();
      t.transform.translation.y = w.position.y();
      t.transform.translation.z = w.position.z();
      t.transform.rotation.w = 1.0;
      tf.transforms.push_back(t);
      tf_.publish(tf);
      // the soil's force and moment on the wheel, about its centre
      const WheelWrench f = wheel.wrench();
      auto m = boost::make_shared<geometry_msgs::WrenchStamped>();
      m->header.stamp = stamp;
      m->header.frame_id = frame_;
      m->wrench.force.x = f.force.x();
      m->wrench.force.y = f.force.y();
      m->wrench.force.z = f.force.z();
      m->wrench.torque.x = f.moment.x();
      m->wrench.torque.y = f.moment.y();
      m->wrench.torque.z = f.moment.z();
      wrench_.publish(m);
    }
    for (; published_ < wheel.samples().size(); ++published_) {
      const WheelSample& x = wheel.samples()[published_];
      auto m = boost::make_shared<WheelRigSample>();
      m->header.stamp = stamp;  // published as soon as the sample is complete
      m->header.frame_id = frame;
      m->t = x.t;
      m->travel = x.travel;
      m->speed = x.speed;
      m->omega = x.omega;
      m->slip = x.slip;
      m->sinkage = x.sinkage;
      m->drawbar_pull = x.drawbar_pull;
      m->torque = x.torque;
      m->vertical_force = x.vertical_force;
      m->contacts = x.contacts;
      sample_.publish(m);
    }
  }

  void PublishResult(const SoilRig& rig, const ros::Time& stamp, const std::string& frame, double wall_time) override {
    // the figures as SingleWheelResultFile writes them
    const auto& wheel = static_cast<const SingleWheelRig&>(rig);
    const SingleWheelParams& p = wheel.params();
    const ResultFile f = wheel.Report();
    const SingleWheelRig::Window w = wheel.Measured();
    const double W = p.Weight(), R = p.tire.radius, nan = std::numeric_limits<double>::quiet_NaN();
    SingleWheelResult m;
    m.header.stamp = stamp;
    m.header.frame_id = frame;
    m.status = f.status();
    m.error = f.error();
    m.scene = p.file;
    m.fidelity = p.bin.level.name;
    m.cohesion_factor = p.bin.strength.cohesion_factor;
    m.friction = p.bin.friction;
    m.cone_index_psi = p.bin.strength.ConeIndex();
    m.drive = SingleWheelParams::DriveName(p.drive);
    m.slip_commanded = p.drive == SingleWheelParams::Drive::kSlip ? p.slip : nan;
    m.torque_commanded = p.drive == SingleWheelParams::Drive::kTorque ? p.torque : nan;
    m.load = W;
    m.dp_over_w = w.dp / W;
    m.dp_over_w_std = w.dp_std / W;
    m.torque_over_wr = w.torque / (W * R);
    m.torque_over_wr_std = w.torque_std / (W * R);
    m.sinkage = w.sinkage;
    m.sinkage_std = w.sinkage_std;
    m.slip = w.slip;
    m.window_samples = w.samples;
    m.particles = wheel.dem().num_alive();
    m.simulated_time = wheel.dem().time();
    m.wall_time = wall_time;
    result_.publish(m);
  }

  void PublishSetupError(const std::string& error) override {
    SingleWheelResult m;
    m.header.stamp = ros::Time(1e-6);
    m.status = "error";
    m.error = error;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    m.cone_index_psi = m.slip_commanded = m.torque_commanded = nan;
    result_.publish(m);
  }

  std::function<bool(const Eigen::Vector3d&)> Section(const SoilRig& rig) const override {
    // a cut through the wheel's mid-plane, seen from -y: the particles between the mid-plane and
    // the tire's far side, so that the soil beside the track does not hide the rut's profile
    const SingleWheelParams& p = static_cast<const SingleWheelRig&>(rig).params();
    const double y0 = p.bin.origin.y(), y1 = y0 + 0.5 * p.tire.width;
    return [y0, y1](const Eigen::Vector3d& x) { return x.y() >= y0 && x.y() <= y1; };
  }

  void AddTools(const SoilRig& rig, std::vector<visualization_msgs::Marker>* markers) override {
    using visualization_msgs::Marker;
    const auto& wheel = static_cast<const SingleWheelRig&>(rig);
    const DemSoilBin& bin = wheel.bin();
    const TireGeometry& tire = wheel.params().tire;
    if (!bin.prepared()) {  // the lid while the soil is prepared
      markers->push_back(WallMarker(bin.dem().wall(bin.lid_wall()), "lid", 0, 0.2f, 0.4f, 0.9f, 0.6f));
      return;
    }
    if (!lid_deleted_) {
      Marker del;
      del.ns = "lid";
      del.id = 0;
      del.action = Marker::DELETE;
      del.pose.orientation.w = 1.0;
      markers->push_back(del);
      lid_deleted_ = true;
    }
    const WheelState& w = wheel.wheel();
    const double R = tire.radius, half = 0.5 * tire.width;
    // the prepared surface the sinkage is measured from, along the bin at the wheel's mid-plane
    const SingleWheelParams& p = wheel.params();
    Marker surface = ColouredMarker("surface", Marker::LINE_LIST, 1.0f, 1.0f, 1.0f, 0.8f);
    surface.scale.x = 0.012;
    for (double x = 0.0; x < p.bin.level.length; x += 0.1) {  // dashed
      surface.points.push_back(MakePoint(p.bin.origin.x() + x, w.position.y(), bin.surface_height()));
      surface.points.push_back(MakePoint(p.bin.origin.x() + std::min(x + 0.05, p.bin.level.length), w.position.y(),
                                     bin.surface_height()));
    }
    markers->push_back(std::move(surface));
    // the tire: the surface the soil touches, at the wheel's pose (see-through: the rut shows)
    if (tire_.points.empty()) {
      tire_ = ColouredMarker("tire", Marker::TRIANGLE_LIST, 0.12f, 0.12f, 0.12f, 0.55f);
      for (const auto& f : tire.soil_mesh.faces)
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d& v = tire.soil_mesh.vertices[f[k]];
          tire_.points.push_back(MakePoint(v.x(), v.y(), v.z()));
        }
    }
    Marker t = tire_;
    SetPose(w.position, w.orientation, &t.pose);
    markers->push_back(std::move(t));
    // two spokes on the side toward -y, turning with the wheel: its spin shows
    Marker spokes = ColouredMarker("spokes", Marker::LINE_LIST, 0.95f, 0.95f, 0.95f, 1.0f);
    spokes.scale.x = 0.03;
    const double r = 0.9 * R, ys = -half - 0.02;
    for (const auto& [a, b] :
         {std::pair(MakePoint(-r, ys, 0), MakePoint(r, ys, 0)), std::pair(MakePoint(0, ys, -r), MakePoint(0, ys, r))}) {
      spokes.points.push_back(a);
      spokes.points.push_back(b);
    }
    SetPose(w.position, w.orientation, &spokes.pose);
    markers->push_back(std::move(spokes));
    // the carriage: the axle, an arm over the tire from the far side (the wrench shows in front
    // of it) and the beam back to the carriage; it moves with the wheel centre and does not turn
    const Eigen::Vector3d& c = w.position;
    Marker axle = ColouredMarker("carriage", Marker::CYLINDER, 0.6f, 0.6f, 0.6f, 1.0f);
    axle.id = 0;
    const double yo = half + 0.12, top = R + 0.35;
    SetPose(c + Eigen::Vector3d(0.0, 0.5 * yo, 0.0), Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())),
            &axle.pose);
    axle.scale.x = axle.scale.y = 0.07;
    axle.scale.z = 1.5 * yo;
    markers->push_back(std::move(axle));
    Marker frame = ColouredMarker("carriage", Marker::LINE_LIST, 1.0f, 0.6f, 0.1f, 1.0f);
    frame.id = 1;
    frame.scale.x = 0.05;
    auto line = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      frame.points.push_back(MakePoint(c.x() + a.x(), c.y() + a.y(), c.z() + a.z()));
      frame.points.push_back(MakePoint(c.x() + b.x(), c.y() + b.y(), c.z() + b.z()));
    };
    line({0, yo, 0}, {0, yo, top});             // the arm
    line({0, yo, top}, {-0.9, yo, top});        // the beam to the carriage
    line({-0.9, yo, top}, {-0.9, yo, top + 0.3});  // the carriage's post
    markers->push_back(std::move(frame));
  }

  std::string StatusText(const SoilRig& rig) const override {
    // the status line on two lines (where the run stands; what it measures now)
    std::string line = rig.StatusLine();
    const size_t at = line.find("  sinkage");
    if (at != std::string::npos) line.replace(at, 2, "\n");
    return line;
  }

  Eigen::Vector3d StatusPosition(const SoilRig& rig) const override {
    // under the bin's floor, at its middle
    const SingleWheelParams& p = static_cast<const SingleWheelRig&>(rig).params();
    return p.bin.origin + Eigen::Vector3d(0.5 * p.bin.level.length, 0.0, -0.3);
  }

 private:
  ros::Publisher tf_, wrench_, sample_, result_;
  const std::string frame_ = "wheel";
  visualization_msgs::Marker tire_;
  long wrench_every_ = 0;
  size_t published_ = 0;
  bool lid_deleted_ = false;
};

}  // namespace

std::unique_ptr<RigTopics> MakeRigTopics(const std::string& kind) {
  if (kind == "cone_penetrometer") return std::make_unique<ConeTopics>();
  if (kind == "single_wheel") return std::make_unique<WheelTopics>();
  throw ConfigError("the rig nodelet has no topics for scenes of kind '" + kind + "'");
}

}  // namespace dem_mobility
