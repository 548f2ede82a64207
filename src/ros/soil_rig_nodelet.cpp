// dem_mobility/SoilRigNodelet: a soil rig scene (the cone penetrometer, the single-wheel rig: any
// kind the core's rig registry knows), stepped here on a thread of its own, with the particles as a
// PointCloud2 (coloured by plastic strain; a cross-section too), the container and the moving tools
// as markers, the rig's own measurements and result as topics (RigTopics), /clock and the result
// file. No physics here: the core computes, the nodelet converts and publishes.
#include <atomic>
#include <chrono>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/dem_visuals.h"
#include "dem_mobility/ros/recorder_watch.h"
#include "dem_mobility/ros/rig_topics.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

class SoilRigNodelet : public nodelet::Nodelet {
 public:
  ~SoilRigNodelet() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    pnh.getParam("result_file", result_file_);  // first: a bad parameter is reported there too
    ros::NodeHandle root;
    clock_ = root.advertise<rosgraph_msgs::Clock>("/clock", 10);
    markers_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/markers", 1, true);
    tools_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/tools", 10);
    cloud_ = nh.advertise<sensor_msgs::PointCloud2>("terrain/particles", 2);
    section_ = nh.advertise<sensor_msgs::PointCloud2>("terrain/particles_section", 2);
    std::string kind;
    try {
      Param(pnh, "result_file", &result_file_);
      Param(pnh, "frame_id", &frame_id_);
      Param(pnh, "wait_for_recorder", &wait_for_recorder_);
      RigCheckpointOptions ck;
      const YamlReader scene = LoadSceneFile(nh, &ck.overrides);
      scene_file_ = scene.file();
      kind = scene.String("scene");
      // the rig's result topic first, so that a rig that cannot start still reports why
      if (IsSoilRigScene(kind)) {
        topics_ = MakeRigTopics(kind);
        topics_->Advertise(nh);
      }
      RateParam(pnh, "cloud_rate", &cloud_rate_);
      RateParam(pnh, "clock_rate", &clock_rate_);
      ResultFile::CheckWritable(result_file_, "parameter " + pnh.resolveName("result_file"));
      Param(pnh, "checkpoint_file", &ck.file);
      Param(pnh, "checkpoint_every", &ck.every);
      Param(pnh, "restart_file", &ck.restart_file);
      if (!(ck.every >= 1.0 && ck.every <= 1e7))
        throw ConfigError("parameter " + pnh.resolveName("checkpoint_every") + ": " + std::to_string(ck.every) +
                          " s: wall seconds between checkpoints are from 1 to 1e7");
      if (!ck.file.empty()) {  // (its temporary file: the checkpoint itself may be the one restarted from)
        ResultFile::CheckWritable(ck.file + ".writing", "parameter " + pnh.resolveName("checkpoint_file"));
        std::remove((ck.file + ".writing").c_str());
      }
      ck_file_ = ck.file;
      checkpoints_ = std::make_unique<RigCheckpoints>(ck);
      // ConfigError naming the file and key for a scene that is no rig, or naming the checkpoint
      // for one that is not of this run
      rig_ = checkpoints_->Start(scene);
      if (checkpoints_->restarted())
        NODELET_INFO("restarted from %s at t = %.3f s (step %ld), phase %s", ck.restart_file.c_str(),
                     checkpoints_->identity().time, checkpoints_->identity().step, rig_->phase().c_str());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      if (topics_) topics_->PublishSetupError(e.what());
      if (!result_file_.empty()) {
        ResultFile f(scene_file_, kind);
        f.SetStatus("error", e.what());
        try {
          f.Write(result_file_);
        } catch (const std::exception& w) {
          NODELET_ERROR("%s", w.what());
        }
      }
      ros::requestShutdown();
      return;
    }
    NODELET_INFO("soil rig '%s' from %s: %d particles", rig_->kind(), scene_file_.c_str(), rig_->dem().num_alive());
    // the bag recorder's failure (a full disk, a file size limit) ends the run with its error
    recorder_.Start(getNodeHandle());
    thread_ = std::thread([this] { Run(); });
  }

  void WaitForRecorder() {
    // the recorder first: nothing of the run may be lost
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (wait_for_recorder_ && !stop_ && ros::ok() &&
           (cloud_.getNumSubscribers() == 0 || tools_.getNumSubscribers() == 0 || !topics_->Subscribed())) {
      if (std::chrono::steady_clock::now() > deadline)  // as the vehicle: no run without its bag
        throw ConfigError("no recorder subscribed to the rig's topics within 60 s (set ~wait_for_recorder false to "
                          "run without one)");
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  void Run() {
    const DemSystem& s = rig_->dem();
    const double dt = s.dt();
    const long cloud_every = std::max(1L, std::lround(1.0 / (cloud_rate_ * dt)));
    const long clock_every = std::max(1L, std::lround(1.0 / (clock_rate_ * dt)));
    auto wall0 = std::chrono::steady_clock::now();
    auto next_progress = wall0 + std::chrono::seconds(10);
    // any error of the run (a numerical failure, a display that cannot be built, memory) ends it
    // with that error in the result: an exception out of this thread would end the whole manager
    // without a result or a closed bag
    try {
      WaitForRecorder();
      wall0 = std::chrono::steady_clock::now();  // (the run's wall time from here)
      next_progress = wall0 + std::chrono::seconds(10);
      PublishContainer();
      PublishFrame();
      while (!rig_->done()) {
        if (recorder_.failed()) {
          rig_->Fail(recorder_.error());
          break;
        }
        if (stop_ || !ros::ok()) {
          checkpoints_->AfterStep(*rig_, /*now=*/true);
          rig_->Fail("interrupted: the run was stopped before its end");
          break;
        }
        rig_->Step();
        const int written = checkpoints_->written();
        checkpoints_->AfterStep(*rig_);
        if (checkpoints_->written() > written)
          NODELET_INFO("checkpoint %s: t = %.3f s, %.1f MB in %.2f s", ck_file_.c_str(), checkpoints_->last_time(),
                       checkpoints_->last_bytes() / 1e6, checkpoints_->last_seconds());
        const long k = s.step_count();
        if ((k & 1023) == 0 && std::chrono::steady_clock::now() > next_progress) {
          next_progress = std::chrono::steady_clock::now() + std::chrono::seconds(10);
          NODELET_INFO("progress: %s", rig_->StatusLine().c_str());
        }
        if (k % clock_every == 0) {
          rosgraph_msgs::Clock c;
          c.clock = ros::Time(s.time());
          clock_.publish(c);
        }
        topics_->PublishProgress(*rig_, frame_id_);
        if (k % cloud_every == 0 || rig_->done()) PublishFrame();
      }
    } catch (const std::exception& e) {
      NODELET_ERROR("soil rig: %s", e.what());
      rig_->Fail(e.what());
      try {
        PublishFrame();  // the state it stopped in
      } catch (const std::exception& f) {
        NODELET_ERROR("soil rig: the last frame: %s", f.what());
      }
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    try {
      ResultFile result = rig_->Report();
      const std::string kept = checkpoints_->Settle(*rig_, &result);
      if (!kept.empty()) NODELET_WARN("%s", kept.c_str());
      if (!checkpoints_->error().empty()) NODELET_ERROR("checkpoint failed: %s", checkpoints_->error().c_str());
      if (!result_file_.empty()) {
        try {
          result.Write(result_file_);
          NODELET_INFO("result: %s", result_file_.c_str());
        } catch (const std::exception& e) {
          NODELET_ERROR("%s", e.what());
        }
      }
      NODELET_INFO("%s: %.2f s simulated in %.1f s; %s", rig_->StatusLine().c_str(), s.time(), wall,
                   result.error().empty() ? "ok" : result.error().c_str());
      topics_->PublishResult(*rig_, ros::Time(s.time() + dt), frame_id_, wall);  // the recorder ends the run on it
    } catch (const std::exception& e) {
      NODELET_FATAL("soil rig: the result could not be made: %s", e.what());
      ros::requestShutdown();
    }
  }

  bool Moving(int w) const {
    for (int m : rig_->moving_walls())
      if (m == w) return true;
    return false;
  }

  void PublishContainer() {
    visualization_msgs::MarkerArray arr;
    const DemSystem& s = rig_->dem();
    int id = 0;
    for (int w = 0; w < s.num_walls(); ++w) {
      if (Moving(w)) continue;
      // the floor opaque, the sides see-through
      const bool floor = s.wall(w).name == "floor";
      visualization_msgs::Marker m = WallMarker(s.wall(w), "container", id++, 0.55f, 0.6f, 0.7f, floor ? 1.0f : 0.25f);
      m.header.frame_id = frame_id_;
      arr.markers.push_back(m);
    }
    markers_.publish(arr);
  }

  void PublishFrame() {
    const DemSystem& s = rig_->dem();
    const ros::Time stamp(std::max(s.time(), 1e-6));
    auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
    ToPointCloud(s, cloud.get());
    cloud->header.stamp = stamp;
    cloud->header.frame_id = frame_id_;
    cloud_.publish(cloud);
    // a cross-section through the tool (the half y >= 0 through the cone's axis, paper fig. 12;
    // the half beyond the wheel's mid-plane), seen from -y
    auto section = boost::make_shared<sensor_msgs::PointCloud2>();
    ToPointCloud(s, section.get(), topics_->Section(*rig_));
    section->header = cloud->header;
    section_.publish(section);
    auto arr = boost::make_shared<visualization_msgs::MarkerArray>();
    topics_->AddTools(*rig_, &arr->markers);
    visualization_msgs::Marker text;
    text.ns = "status";
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.action = visualization_msgs::Marker::ADD;
    text.pose.orientation.w = 1.0;
    const Eigen::Vector3d at = topics_->StatusPosition(*rig_);  // clear of the tools and the soil
    text.pose.position.x = at.x();
    text.pose.position.y = at.y();
    text.pose.position.z = at.z();
    text.scale.z = 0.12;
    text.color.r = text.color.g = text.color.b = text.color.a = 1.0f;
    text.text = topics_->StatusText(*rig_);
    arr->markers.push_back(text);
    for (auto& m : arr->markers) {
      m.header.stamp = stamp;
      m.header.frame_id = frame_id_;
    }
    tools_.publish(arr);
  }

  std::unique_ptr<RigCheckpoints> checkpoints_;
  std::unique_ptr<SoilRig> rig_;
  std::unique_ptr<RigTopics> topics_;
  std::string scene_file_, frame_id_ = "map", result_file_, ck_file_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  RecorderWatch recorder_;  ///< the bag recorder's failure ends the run with its error
  ros::Publisher clock_, markers_, tools_, cloud_, section_;
  double cloud_rate_ = 20.0, clock_rate_ = 100.0;
  bool wait_for_recorder_ = true;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::SoilRigNodelet, nodelet::Nodelet)
