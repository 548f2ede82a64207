// dem_mobility/TerrainNodelet: the terrain of a run. Two kinds of scene:
// - vehicle scenes: the terrain side of the lock-step exchange. Builds the scene's terrain model
//   (core), answers each WheelStates with the WheelWrenches of the same step, and shows the
//   surface in rviz;
// - soil rig scenes (the cone penetrometer): the DEM soil with its rigid tools, stepped here, with
//   the particles as a PointCloud2 (coloured by plastic strain), the container and tools as
//   markers, the CI history and the result as topics, and /clock.
// No physics here: the core computes, the nodelet converts and publishes.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>
#include <yaml-cpp/yaml.h>

#include "dem_mobility/ConeIndexResult.h"
#include "dem_mobility/ConePenetration.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/scenes/cone_penetrometer.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/dem_visuals.h"

namespace dem_mobility {

class TerrainNodelet : public nodelet::Nodelet {
 public:
  ~TerrainNodelet() override {
    stop_ = true;
    if (rig_thread_.joinable()) rig_thread_.join();
    responder_.reset();  // the vehicle learns at once that its terrain is gone
    if (served_ > 0) NODELET_INFO("terrain: %lu exchanges answered", static_cast<unsigned long>(served_));
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string transport;
    std::unique_ptr<ExchangeServer<WheelStates, WheelWrenches>> server;
    std::string kind;
    try {
      const YamlReader y = LoadSceneFile(nh);
      kind = y.Has("scene") ? y.String("scene") : "";
    } catch (const std::exception&) {  // reported below, by the loader of the scene's kind
    }
    if (kind == "cone_penetrometer") return StartRig(nh, pnh);
    try {
      const RoadSceneParams scene = LoadScene(nh);
      const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
      pnh.param<std::string>("frame_id", frame_id_, "odom");
      model_ = LoadTerrainModel(scene.terrain_file, scene.vehicle_file);
      server = std::make_unique<ExchangeServer<WheelStates, WheelWrenches>>(
          nh, transport, nh.resolveName("exchange/terrain"), "exchange/wheel_states", "exchange/wheel_wrenches", timing);
      NODELET_INFO("terrain '%s' from %s (%zu triangles), exchange over %s", model_->kind().c_str(),
                   scene.terrain_file.c_str(), model_->Surface().faces.size(), transport.c_str());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      failed_ = RefuseExchange<WheelStates, WheelWrenches>(transport, nh.resolveName("exchange/terrain"),
                                                          std::string("the terrain could not start: ") + e.what());
      return;
    }
    markers_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/markers", 1, true);
    PublishSurface();
    responder_ = std::make_unique<ExchangeResponder<WheelStates, WheelWrenches>>(
        std::move(server), "terrain", [this](const WheelStates& req) { return Answer(req); },
        [this](const std::string& m) { NODELET_ERROR("%s", m.c_str()); },
        [this](const std::string& m) { NODELET_INFO("%s", m.c_str()); });
  }

  /// The wrenches of one exchange (the model's, converted).
  WheelWrenches::ConstPtr Answer(const WheelStates& req) {
    FromMsg(req, &states_);
    model_->Compute(static_cast<long>(req.step), req.header.stamp.toSec(), states_, &wrenches_);
    auto resp = boost::make_shared<WheelWrenches>();
    resp->header.stamp = req.header.stamp;
    resp->header.frame_id = req.header.frame_id;
    resp->step = req.step;
    resp->served = ++served_;
    ToMsg(wrenches_, resp.get());
    return resp;
  }

  void PublishSurface() {
    const TriMesh& mesh = model_->Surface();
    visualization_msgs::MarkerArray arr;
    visualization_msgs::Marker m;
    m.header.frame_id = frame_id_;
    m.ns = "terrain_surface";
    m.id = 0;
    m.type = visualization_msgs::Marker::TRIANGLE_LIST;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    m.scale.x = m.scale.y = m.scale.z = 1.0;
    m.color.r = 0.42f;
    m.color.g = 0.42f;
    m.color.b = 0.45f;
    m.color.a = 1.0f;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
    for (const auto& f : mesh.faces)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& v = mesh.vertices[f[k]];
        geometry_msgs::Point p;
        p.x = v.x();
        p.y = v.y();
        p.z = v.z();
        m.points.push_back(p);
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
    arr.markers.push_back(m);
    // cross lines every 5 m so that motion along the surface is visible
    visualization_msgs::Marker l = m;
    l.ns = "terrain_lines";
    l.type = visualization_msgs::Marker::LINE_LIST;
    l.points.clear();
    l.scale.x = 0.05;
    l.color.r = l.color.g = l.color.b = 0.9f;
    for (double x = std::ceil(lo.x() / 5.0) * 5.0; x <= hi.x(); x += 5.0) {
      geometry_msgs::Point a, b;
      a.x = b.x = x;
      a.y = lo.y();
      b.y = hi.y();
      a.z = b.z = hi.z() + 0.005;
      l.points.push_back(a);
      l.points.push_back(b);
    }
    arr.markers.push_back(l);
    markers_.publish(arr);
  }


  // ---- soil rig scenes ------------------------------------------------------------------------

  void StartRig(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
    pnh.param<std::string>("frame_id", frame_id_, "map");
    pnh.param<std::string>("result_file", result_file_, "");
    pnh.param("cloud_rate", cloud_rate_, cloud_rate_);
    pnh.param("clock_rate", clock_rate_, clock_rate_);
    pnh.param("wait_for_recorder", wait_for_recorder_, true);
    ros::NodeHandle root;
    clock_ = root.advertise<rosgraph_msgs::Clock>("/clock", 10);
    markers_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/markers", 1, true);
    tools_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/tools", 10);
    cloud_ = nh.advertise<sensor_msgs::PointCloud2>("terrain/particles", 2);
    section_ = nh.advertise<sensor_msgs::PointCloud2>("terrain/particles_section", 2);
    penetration_ = nh.advertise<ConePenetration>("cone/penetration", 100);
    result_ = nh.advertise<ConeIndexResult>("result", 1, true);
    try {
      if (!(cloud_rate_ > 0.0)) throw ConfigError("parameter " + pnh.resolveName("cloud_rate") + " must be > 0 Hz");
      if (!(clock_rate_ > 0.0)) throw ConfigError("parameter " + pnh.resolveName("clock_rate") + " must be > 0 Hz");
      if (!result_file_.empty()) {
        const std::filesystem::path parent = std::filesystem::path(result_file_).parent_path();
        if (!parent.empty()) std::filesystem::create_directories(parent);
        if (!std::ofstream(result_file_, std::ios::app))
          throw ConfigError("parameter " + pnh.resolveName("result_file") + ": cannot write '" + result_file_ + "'");
      }
      cone_params_ = ConeParams::Read(LoadSceneFile(nh));
      rig_ = std::make_unique<ConePenetrometer>(cone_params_);
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      ConeIndexResult m;
      m.header.stamp = ros::Time(1e-6);
      m.status = "error";
      m.error = e.what();
      result_.publish(m);
      if (!result_file_.empty()) {
        YAML::Emitter y;
        y << YAML::BeginMap << YAML::Key << "status" << YAML::Value << "error" << YAML::Key << "error" << YAML::Value
          << e.what() << YAML::EndMap;
        std::ofstream(result_file_) << y.c_str() << "\n";
      }
      ros::requestShutdown();
      return;
    }
    NODELET_INFO("terrain: cone penetrometer '%s', level '%s', f %g, mu %g, %d particles", cone_params_.file.c_str(),
                 cone_params_.level.name.c_str(), cone_params_.cohesion_factor, cone_params_.friction,
                 rig_->dem().num_alive());
    rig_thread_ = std::thread([this] { RunRig(); });
  }

  void RunRig() {
    // the recorder first: nothing of the run may be lost
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (wait_for_recorder_ && !stop_ && ros::ok() &&
           (cloud_.getNumSubscribers() == 0 || penetration_.getNumSubscribers() == 0 ||
            result_.getNumSubscribers() == 0 || tools_.getNumSubscribers() == 0)) {
      if (std::chrono::steady_clock::now() > deadline) {
        NODELET_WARN("terrain: no recorder after 60 s; running without");
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const DemSystem& s = rig_->dem();
    const double dt = s.dt();
    const long cloud_every = std::max(1L, std::lround(1.0 / (cloud_rate_ * dt)));
    const long clock_every = std::max(1L, std::lround(1.0 / (clock_rate_ * dt)));
    PublishContainer();
    PublishFrame();
    const auto wall0 = std::chrono::steady_clock::now();
    auto next_progress = wall0 + std::chrono::seconds(10);
    size_t published = 0;
    try {
      while (!rig_->done()) {
        if (stop_ || !ros::ok()) {
          rig_->Fail("interrupted: the run was stopped before its end");
          break;
        }
        rig_->Step();
        const long k = s.step_count();
        if ((k & 1023) == 0 && std::chrono::steady_clock::now() > next_progress) {
          next_progress = std::chrono::steady_clock::now() + std::chrono::seconds(10);
          const double ci = rig_->samples().empty() ? 0.0 : rig_->samples().back().ci_psi;
          NODELET_INFO("progress: t = %.3f s, %s, tip depth %.3f / %.3f m, CI %.1f psi", s.time(),
                       ConePenetrometer::PhaseName(rig_->phase()),
                       rig_->phase() == ConePenetrometer::Phase::kPenetrate ? rig_->tip_depth() : 0.0,
                       cone_params_.level.ci_to, ci);
        }
        if (k % clock_every == 0) {
          rosgraph_msgs::Clock c;
          c.clock = ros::Time(s.time());
          clock_.publish(c);
        }
        for (; published < rig_->samples().size(); ++published) PublishSample(rig_->samples()[published]);
        if (k % cloud_every == 0 || rig_->done()) PublishFrame();
      }
    } catch (const SimulationError& e) {
      NODELET_ERROR("terrain: %s", e.what());
      rig_->Fail(e.what());
      PublishFrame();
    }
    const ConeResult r = rig_->Result();
    ConeIndexResult m;
    m.header.stamp = ros::Time(s.time() + dt);
    m.header.frame_id = frame_id_;
    m.scene = cone_params_.file;
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
    m.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    m.status = r.error.empty() ? "ok" : (r.error.rfind("interrupted", 0) == 0 ? "interrupted" : "error");
    m.error = r.error;
    if (!result_file_.empty()) {
      try {
        WriteConeResult(r, cone_params_, result_file_);
        NODELET_INFO("result: %s", result_file_.c_str());
      } catch (const std::exception& e) {
        NODELET_ERROR("%s", e.what());
      }
    }
    NODELET_INFO("cone index %.2f psi (f %g, mu %g, level '%s'): %.2f s simulated in %.1f s; %s", r.ci_psi,
                 r.cohesion_factor, r.friction, r.level.c_str(), r.sim_time, m.wall_time,
                 r.error.empty() ? "ok" : r.error.c_str());
    result_.publish(m);  // the recorder closes the bag on it and ends the run
  }

  void PublishSample(const ConeSample& c) {
    auto m = boost::make_shared<ConePenetration>();
    m->header.stamp = ros::Time(rig_->dem().time());  // published as soon as the sample is complete
    m->header.frame_id = frame_id_;
    m->phase = ConePenetrometer::PhaseName(rig_->phase());
    m->tip_depth = c.depth;
    m->speed = c.speed;
    m->force = c.force;
    m->cone_index_psi = c.ci_psi;
    penetration_.publish(m);
  }

  void PublishContainer() {
    visualization_msgs::MarkerArray arr;
    const DemSystem& s = rig_->dem();
    int id = 0;
    for (int w = 0; w < s.num_walls(); ++w) {
      if (w == rig_->cone_wall() || w == rig_->rod_wall() || w == rig_->lid_wall()) continue;
      visualization_msgs::Marker m = WallMarker(s.wall(w), "container", id++, 0.55f, 0.6f, 0.7f,
                                                w == rig_->floor_wall() ? 1.0f : 0.25f);
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
    // the half y >= 0: a cross-section through the cone's axis, seen from -y (paper fig. 12)
    auto section = boost::make_shared<sensor_msgs::PointCloud2>();
    ToPointCloud(s, section.get(), [](const Eigen::Vector3d& x) { return x.y() >= 0.0; });
    section->header = cloud->header;
    section_.publish(section);
    auto arr = boost::make_shared<visualization_msgs::MarkerArray>();
    auto add = [&](visualization_msgs::Marker m) {
      m.header.stamp = stamp;
      m.header.frame_id = frame_id_;
      arr->markers.push_back(std::move(m));
    };
    add(WallMarker(s.wall(rig_->cone_wall()), "cone", 0, 0.85f, 0.3f, 0.1f, 1.0f));
    add(WallMarker(s.wall(rig_->rod_wall()), "cone", 1, 0.7f, 0.7f, 0.7f, 1.0f));
    add(WallMarker(s.wall(rig_->lid_wall()), "lid", 0, 0.2f, 0.4f, 0.9f, 0.6f));
    visualization_msgs::Marker text;
    text.ns = "status";
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.action = visualization_msgs::Marker::ADD;
    text.pose.orientation.w = 1.0;
    text.pose.position.z = -0.25;  // under the container's floor, clear of the rod and the soil
    text.scale.z = 0.12;
    text.color.r = text.color.g = text.color.b = text.color.a = 1.0f;
    char buf[160];
    if (rig_->phase() == ConePenetrometer::Phase::kPenetrate || rig_->phase() == ConePenetrometer::Phase::kDone) {
      const double ci = rig_->samples().empty() ? 0.0 : rig_->samples().back().ci_psi;
      std::snprintf(buf, sizeof buf, "t %.2f s  %s  tip depth %.3f m  CI %.1f psi", s.time(),
                    ConePenetrometer::PhaseName(rig_->phase()), rig_->tip_depth(), ci);
    } else {
      std::snprintf(buf, sizeof buf, "t %.2f s  %s", s.time(), ConePenetrometer::PhaseName(rig_->phase()));
    }
    text.text = buf;
    add(text);
    tools_.publish(arr);
  }

  std::unique_ptr<ConePenetrometer> rig_;
  ConeParams cone_params_;
  std::thread rig_thread_;
  std::atomic<bool> stop_{false};
  ros::Publisher clock_, tools_, cloud_, section_, penetration_, result_;
  std::string result_file_;
  double cloud_rate_ = 20.0, clock_rate_ = 100.0;
  bool wait_for_recorder_ = true;

  std::unique_ptr<TerrainModel> model_;
  std::unique_ptr<ExchangeResponder<WheelStates, WheelWrenches>> responder_;
  std::shared_ptr<Channel<WheelStates, WheelWrenches>> failed_;  ///< held closed when the setup failed
  ros::Publisher markers_;
  std::string frame_id_;
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
  uint64_t served_ = 0;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::TerrainNodelet, nodelet::Nodelet)
