// dem_mobility/TerrainNodelet: the terrain side of the lock-step exchange of a vehicle scene. Builds
// the scene's terrain model (core, any kind the terrain registry knows, with the scene's
// terrain_overrides), answers each WheelStates with the WheelWrenches of the same step (synchronize,
// wrenches, advance to the next exchange), and shows the surface in rviz. A terrain with particles
// (the DEM soil) is prepared on a thread of its own (the manager keeps loading the other nodelets;
// the vehicle waits for the first answer) and shows its particles and tools (the moving patch's
// leveling cylinder and plate, bounding sphere, box and emitter zone) every 1 / cloud_rate of
// simulated time. The service terrain/report gives the terrain's own figures for the run's result
// (and, within the manager's process, TerrainFiguresBoard: when ROS is shutting down, and once this
// nodelet has unloaded, its last figures).
// No physics here: the core computes, the nodelet converts.

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "dem_mobility/TerrainReport.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/mobility/mobility_params.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/core_names.h"
#include "dem_mobility/ros/dem_visuals.h"
#include "dem_mobility/ros/terrain_figures_board.h"

namespace dem_mobility {

class TerrainNodelet : public nodelet::Nodelet {
 public:
  ~TerrainNodelet() override {
    stop_prepare_ = true;  // a preparation in progress stops within a step
    if (prepare_.joinable()) prepare_.join();
    responder_.reset();  // the vehicle learns at once that its terrain is gone
    // the figures of the last exchange answered, for a vehicle writing its result after this (Ctrl-C:
    // roslaunch unloads the nodelets while the vehicle finishes)
    if (!report_name_.empty()) TerrainFiguresBoard::Close(report_name_);
    if (served_ > 0) NODELET_INFO("terrain: %lu exchanges answered", static_cast<unsigned long>(served_));
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string transport;
    MobilityRunParams scene;
    ExchangeTiming timing;
    exchange_name_ = nh.resolveName("exchange/terrain");
    try {
      scene = LoadScene(nh);
      timing = LoadExchangeTiming(pnh, &transport);
      Param(pnh, "frame_id", &frame_id_);
      RateParam(pnh, "cloud_rate", &cloud_rate_);
      Param(pnh, "prepared_soil_cache", &prepared_soil_cache_);
    } catch (const std::exception& e) {
      Refuse(transport, e.what());
      return;
    }
    markers_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/markers", 1, true);
    cloud_ = nh.advertise<sensor_msgs::PointCloud2>("terrain/particles", 2);
    tools_ = nh.advertise<visualization_msgs::MarkerArray>("terrain/tools", 2);
    report_ = nh.advertiseService("terrain/report", &TerrainNodelet::Report, this);
    report_name_ = report_.getService();
    TerrainFiguresBoard::Open(report_name_, [this]() { return Figures(); });
    // a DEM soil takes minutes to prepare: not in the manager's loading thread
    prepare_ = std::thread([this, scene, transport, timing, nh]() mutable { Prepare(nh, scene, transport, timing); });
  }

  void Prepare(ros::NodeHandle nh, const MobilityRunParams& scene, const std::string& transport,
               const ExchangeTiming& timing) {
    std::unique_ptr<ExchangeServer<WheelStates, WheelWrenches>> server;
    try {
      // (the file is read once, by LoadTerrainModel: a DEM soil's progress lines say what it prepares)
      NODELET_INFO("terrain from %s: loading ...", scene.terrain_file.c_str());
      const auto t0 = std::chrono::steady_clock::now();
      // a shutdown (SIGINT, SIGTERM, the manager unloading this nodelet) stops the preparation
      // within a step: the exchange is then closed with the reason, so the vehicle's wait ends
      PreparationHooks hooks;
      hooks.stop = [this] { return stop_prepare_.load() || !ros::ok(); };
      hooks.progress = [this](const PreparationProgress& at) {
        NODELET_INFO("terrain: preparing the soil: %s", at.Line().c_str());
      };
      hooks.progress_every = 30.0;
      hooks.prepared_soil_cache = prepared_soil_cache_;
      // what the terrain is, for the report (the vehicle's description of it) before it prepares
      hooks.described = [this](const TerrainDescription& d) {
        std::lock_guard<std::mutex> lock(mutex_);
        description_ = d;
      };
      std::unique_ptr<TerrainModel> model =
          LoadTerrainModel(scene.terrain_file, TerrainVehicleOf(VehicleSpec::Load(scene.vehicle_file)),
                           scene.terrain_overrides, hooks);
      model->SetGravity(scene.Gravity());  // the soil on the grade, as in-process
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      server = std::make_unique<ExchangeServer<WheelStates, WheelWrenches>>(
          nh, transport, exchange_name_, "exchange/wheel_states", "exchange/wheel_wrenches", timing);
      const TerrainDisplay shown = model->Display();
      if (shown.dem)
        NODELET_INFO("terrain '%s' from %s: %d particles, prepared in %.1f s; particles every %.3g s of simulated "
                     "time on %s",
                     model->description().model.c_str(), scene.terrain_file.c_str(), shown.dem->num_alive(), wall,
                     1.0 / cloud_rate_, cloud_.getTopic().c_str());
      NODELET_INFO("terrain '%s' from %s (%zu triangles), exchange over %s", model->description().model.c_str(),
                   scene.terrain_file.c_str(), model->Surface().faces.size(), transport.c_str());
      std::lock_guard<std::mutex> lock(mutex_);
      model_ = std::move(model);
      PublishSurface();
    } catch (const core::Interrupted& e) {  // a shutdown during the preparation: no failure of the terrain's
      Refuse(transport, e.what(), false);
      return;
    } catch (const std::exception& e) {
      Refuse(transport, e.what());
      return;
    }
    responder_ = std::make_unique<ExchangeResponder<WheelStates, WheelWrenches>>(
        std::move(server), "terrain", [this](const WheelStates& req) { return Answer(req); },
        [this](const std::string& m) { NODELET_ERROR("%s", m.c_str()); },
        [this](const std::string& m) { NODELET_INFO("%s", m.c_str()); });
  }

  /// The terrain could not start: said clearly (`fatal`: an error; else, a shutdown, a warning); the
  /// vehicle finds the exchange closed with the reason.
  void Refuse(const std::string& transport, const std::string& what, bool fatal = true) {
    if (fatal)
      NODELET_FATAL("%s", what.c_str());
    else
      NODELET_WARN("%s", what.c_str());
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = what;
    }
    failed_ = RefuseExchange<WheelStates, WheelWrenches>(transport.empty() ? "inline" : transport, exchange_name_,
                                                        "the terrain could not start: " + what);
  }

  /// The wrenches of one exchange (the model's, converted); the particles and tools of the state
  /// the wheels are synchronized with, when a display frame is due.
  WheelWrenches::ConstPtr Answer(const WheelStates& req) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = req.header.stamp.toSec();
    FromMsg(req, &states_);
    model_->Synchronize(static_cast<long>(req.step), t, states_);
    model_->GetWrenches(&wrenches_);
    const TerrainDisplay shown = model_->Display();
    if (shown.dem && t >= next_frame_ - 1e-9) {
      PublishFrame(shown, req.header.stamp);
      // from the step's time on, so that a long exchange interval does not bunch the frames
      next_frame_ = (std::floor(t * cloud_rate_ + 1e-6) + 1.0) / cloud_rate_;
    }
    model_->Advance(req.time_step);
    time_ = t + req.time_step;
    auto resp = boost::make_shared<WheelWrenches>();
    resp->header.stamp = req.header.stamp;
    resp->header.frame_id = req.header.frame_id;
    resp->step = req.step;
    resp->served = ++served_;
    ToMsg(wrenches_, resp.get());
    return resp;
  }

  bool Report(TerrainReport::Request&, TerrainReport::Response& res) {
    res = Figures();
    return true;
  }

  /// The terrain's own figures now (the service's answer).
  TerrainReport::Response Figures() {
    TerrainReport::Response res;
    std::lock_guard<std::mutex> lock(mutex_);
    res.time = time_;
    res.served = served_;
    res.model = description_.model;
    res.file = description_.file;
    res.cone_index_psi = description_.cone_index;
    res.time_step = description_.time_step;
    res.fidelity = description_.fidelity;
    if (!model_) {
      res.error = error_.empty() ? "the terrain is not prepared yet" : "the terrain could not start: " + error_;
      res.figures = "{}";
      return res;
    }
    ResultFile f("", "");
    model_->Describe(&f);
    // the figures alone: the schema's own keys (scene, kind, status, error) belong to the run
    const YAML::Node all = YAML::Load(f.Text());
    YAML::Emitter e;
    e.SetDoublePrecision(17);
    e << YAML::BeginMap;
    for (const auto& kv : all) {
      const std::string key = kv.first.as<std::string>();
      if (key == "scene" || key == "kind" || key == "status" || key == "error") continue;
      e << YAML::Key << key << YAML::Value << kv.second;
    }
    e << YAML::EndMap;
    res.figures = e.c_str();
    return res;
  }

  // --- display


  visualization_msgs::Marker Marker(const std::string& ns, int type, float r, float g, float b, float a) const {
    visualization_msgs::Marker m = ColouredMarker(ns, type, r, g, b, a);
    m.header.frame_id = frame_id_;
    return m;
  }

  void PublishFrame(const TerrainDisplay& d, const ros::Time& stamp) {
    const DemSystem& s = *d.dem;
    auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
    ToPointCloud(s, &first_shown_, cloud.get());
    cloud->header.stamp = stamp;
    cloud->header.frame_id = frame_id_;
    cloud_.publish(cloud);

    auto arr = boost::make_shared<visualization_msgs::MarkerArray>();
    static const float kTool[][4] = {{0.75f, 0.75f, 0.8f, 1.0f}, {0.35f, 0.55f, 0.85f, 0.8f}};
    int k = 0;
    for (int w : d.walls) {
      const float* c = kTool[std::min(k++, 1)];
      visualization_msgs::Marker m = WallMarker(s.wall(w), s.wall(w).name, 0, c[0], c[1], c[2], c[3]);
      m.header.frame_id = frame_id_;
      arr->markers.push_back(m);
    }
    if (d.patch) {
      const double y0 = -0.5 * d.box_width, y1 = 0.5 * d.box_width, z0 = d.floor_z, z1 = d.floor_z + d.box_height;
      // the bounding sphere: three great circles (a translucent ball would wash the soil out)
      auto sphere = Marker("patch_sphere", visualization_msgs::Marker::LINE_LIST, 0.3f, 0.8f, 1.0f, 0.35f);
      sphere.scale.x = 0.02;
      const Eigen::Vector3d c = d.sphere_centre;
      const double r = d.sphere_radius;
      const int n = 72;
      for (int plane = 0; plane < 3; ++plane)
        for (int i = 0; i < n; ++i)
          for (int j : {i, i + 1}) {
            const double a = 2.0 * M_PI * j / n, u = r * std::cos(a), v = r * std::sin(a);
            const Eigen::Vector3d q = plane == 0 ? Eigen::Vector3d(u, v, 0) : plane == 1 ? Eigen::Vector3d(u, 0, v)
                                                                                         : Eigen::Vector3d(0, u, v);
            sphere.points.push_back(MakePoint(c.x() + q.x(), c.y() + q.y(), c.z() + q.z()));
          }
      arr->markers.push_back(sphere);
      // the box that follows the vehicle: its twelve edges
      auto box = Marker("patch_box", visualization_msgs::Marker::LINE_LIST, 1.0f, 1.0f, 1.0f, 0.7f);
      box.scale.x = 0.025;
      const double xs[2] = {d.box_rear, d.box_front}, ys[2] = {y0, y1}, zs[2] = {z0, z1};
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          box.points.push_back(MakePoint(xs[0], ys[a], zs[b]));
          box.points.push_back(MakePoint(xs[1], ys[a], zs[b]));
          box.points.push_back(MakePoint(xs[a], ys[0], zs[b]));
          box.points.push_back(MakePoint(xs[a], ys[1], zs[b]));
          box.points.push_back(MakePoint(xs[a], ys[b], zs[0]));
          box.points.push_back(MakePoint(xs[a], ys[b], zs[1]));
        }
      arr->markers.push_back(box);
      if (!d.strips.empty()) {
        // soil only under the wheel tracks: each strip's walls, and the rigid floor between and
        // beside the strips (its outline at its height)
        auto strips = Marker("patch_strips", visualization_msgs::Marker::LINE_LIST, 1.0f, 1.0f, 1.0f, 0.5f);
        strips.scale.x = 0.02;
        for (const auto& b : d.strips)
          for (double y : {b.first, b.second})
            for (double z : {z0, z1}) {
              strips.points.push_back(MakePoint(xs[0], y, z));
              strips.points.push_back(MakePoint(xs[1], y, z));
              if (z == z0)
                for (double x : xs) {
                  strips.points.push_back(MakePoint(x, y, z0));
                  strips.points.push_back(MakePoint(x, y, z1));
                }
            }
        std::vector<double> edges = {y0};
        for (const auto& b : d.strips) {
          edges.push_back(b.first);
          edges.push_back(b.second);
        }
        edges.push_back(y1);
        for (size_t i = 0; i + 1 < edges.size(); i += 2)
          for (double y : {edges[i], edges[i + 1]}) {
            strips.points.push_back(MakePoint(xs[0], y, d.strip_floor_z));
            strips.points.push_back(MakePoint(xs[1], y, d.strip_floor_z));
          }
        arr->markers.push_back(strips);
      }
      // the emitter's zone: the layer being filled, floor to the prepared surface
      auto emitter = Marker("patch_emitter", visualization_msgs::Marker::CUBE, 1.0f, 0.55f, 0.0f, 0.45f);
      const double ztop = surface_z_;
      emitter.pose.position = MakePoint(0.5 * (d.emitter_from + d.emitter_to), 0.0, 0.5 * (z0 + ztop));
      emitter.scale.x = std::max(d.emitter_to - d.emitter_from, 0.02);
      emitter.scale.y = d.box_width;
      emitter.scale.z = std::max(ztop - z0, 0.02);
      arr->markers.push_back(emitter);
    }
    for (auto& m : arr->markers) m.header.stamp = stamp;
    tools_.publish(arr);
  }

  void PublishSurface() {
    const TriMesh& mesh = model_->Surface();
    // a terrain with particles: its surface only hints where the soil goes on (translucent)
    const bool particles = model_->Display().dem != nullptr;
    visualization_msgs::MarkerArray arr;
    auto m = Marker("terrain_surface", visualization_msgs::Marker::TRIANGLE_LIST, 0.42f, 0.42f, 0.45f, 1.0f);
    if (particles) {
      m.color.r = 0.55f;
      m.color.g = 0.45f;
      m.color.b = 0.35f;
      m.color.a = 0.25f;
    }
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
    for (const auto& f : mesh.faces)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& v = mesh.vertices[f[k]];
        m.points.push_back(MakePoint(v.x(), v.y(), v.z()));
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
    surface_z_ = hi.z();
    arr.markers.push_back(m);
    // cross lines every 5 m so that motion along the surface is visible
    auto l = Marker("terrain_lines", visualization_msgs::Marker::LINE_LIST, 0.9f, 0.9f, 0.9f, particles ? 0.5f : 1.0f);
    l.scale.x = 0.05;
    for (double x = std::ceil(lo.x() / 5.0) * 5.0; x <= hi.x(); x += 5.0) {
      l.points.push_back(MakePoint(x, lo.y(), hi.z() + 0.005));
      l.points.push_back(MakePoint(x, hi.y(), hi.z() + 0.005));
    }
    arr.markers.push_back(l);
    markers_.publish(arr);
  }

  std::mutex mutex_;  ///< the model: the exchange (whatever thread runs it) and the report
  std::unique_ptr<TerrainModel> model_;
  TerrainDescription description_;  ///< what the terrain is, once it has read its file (the report's)
  std::string error_;
  std::unique_ptr<ExchangeResponder<WheelStates, WheelWrenches>> responder_;
  std::string report_name_;  ///< the report service's name (its entry on TerrainFiguresBoard)
  std::shared_ptr<Channel<WheelStates, WheelWrenches>> failed_;  ///< held closed when the setup failed
  std::atomic<bool> stop_prepare_{false};
  std::thread prepare_;
  ros::Publisher markers_, cloud_, tools_;
  ros::ServiceServer report_;
  std::string frame_id_ = "odom", exchange_name_;
  std::string prepared_soil_cache_;  ///< ~prepared_soil_cache: the folder of prepared soils ("" none)
  double cloud_rate_ = 10.0, next_frame_ = 0.0, time_ = 0.0, surface_z_ = 0.0;
  std::vector<float> first_shown_;  ///< each particle's plastic strain when first shown (by ID)
  std::vector<WheelState> states_;
  std::vector<WheelWrench> wrenches_;
  uint64_t served_ = 0;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::TerrainNodelet, nodelet::Nodelet)
