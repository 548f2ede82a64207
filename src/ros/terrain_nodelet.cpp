// dem_mobility/TerrainNodelet: the terrain side of the lock-step exchange of a vehicle scene. Builds
// the scene's terrain model (core, any kind the terrain registry knows), answers each WheelStates
// with the WheelWrenches of the same step (synchronize, wrenches, advance to the next exchange),
// and shows the surface in rviz. No physics here: the core computes, the nodelet converts.

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <cmath>
#include <visualization_msgs/MarkerArray.h>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

class TerrainNodelet : public nodelet::Nodelet {
 public:
  ~TerrainNodelet() override {
    responder_.reset();  // the vehicle learns at once that its terrain is gone
    if (served_ > 0) NODELET_INFO("terrain: %lu exchanges answered", static_cast<unsigned long>(served_));
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string transport;
    std::unique_ptr<ExchangeServer<WheelStates, WheelWrenches>> server;
    try {
      const MobilityRunParams scene = LoadScene(nh);
      const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
      pnh.param<std::string>("frame_id", frame_id_, "odom");
      model_ = LoadTerrainModel(scene.terrain_file, TerrainVehicle{VehicleSpec::Load(scene.vehicle_file).tire, kWheels});
      server = std::make_unique<ExchangeServer<WheelStates, WheelWrenches>>(
          nh, transport, nh.resolveName("exchange/terrain"), "exchange/wheel_states", "exchange/wheel_wrenches", timing);
      NODELET_INFO("terrain '%s' from %s (%zu triangles), exchange over %s", model_->description().model.c_str(),
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
    model_->Synchronize(static_cast<long>(req.step), req.header.stamp.toSec(), states_);
    model_->GetWrenches(&wrenches_);
    model_->Advance(req.time_step);
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
