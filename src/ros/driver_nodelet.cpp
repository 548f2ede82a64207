// dem_mobility/DriverNodelet: the driver side of the lock-step exchange. Answers each DriverInput
// (speed, drive-shaft speed, lateral offset and heading) with the scene driver's command (core
// SpeedDriver: profile, speed controller, clamp between the engine-brake and WOT curves, brakes,
// steering to the start line).
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "dem_mobility/core/mobility/ports.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

class DriverNodelet : public nodelet::Nodelet {
 public:
  ~DriverNodelet() override {
    responder_.reset();  // the vehicle learns at once that its driver is gone
    if (served_ > 0) NODELET_INFO("driver: %lu commands given", static_cast<unsigned long>(served_));
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string transport;
    std::unique_ptr<ExchangeServer<dem_mobility::DriverInput, dem_mobility::DriverCommand>> server;
    try {
      const MobilityRunParams scene = LoadScene(nh);
      const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
      driver_ = std::make_unique<SceneDriver>(scene.driver, VehicleSpec::Load(scene.vehicle_file));
      server = std::make_unique<ExchangeServer<dem_mobility::DriverInput, dem_mobility::DriverCommand>>(
          nh, transport, nh.resolveName("exchange/driver"), "exchange/driver_input", "exchange/driver_command", timing);
      NODELET_INFO("driver: %.2f m/s^2 toward %.1f m/s, every %.4g s, exchange over %s", scene.driver.accel,
                   scene.driver.v_max, scene.driver.control_period, transport.c_str());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      failed_ = RefuseExchange<dem_mobility::DriverInput, dem_mobility::DriverCommand>(transport, nh.resolveName("exchange/driver"),
                                                          std::string("the driver could not start: ") + e.what());
      return;
    }
    responder_ = std::make_unique<ExchangeResponder<dem_mobility::DriverInput, dem_mobility::DriverCommand>>(
        std::move(server), "driver", [this](const dem_mobility::DriverInput& req) { return Answer(req); },
        [this](const std::string& m) { NODELET_ERROR("%s", m.c_str()); },
        [this](const std::string& m) { NODELET_INFO("%s", m.c_str()); });
  }

  /// The driver's command for one control step.
  dem_mobility::DriverCommand::ConstPtr Answer(const dem_mobility::DriverInput& req) {
    const core::DriverCommand c = driver_->Exchange(FromMsg(req));
    auto resp = boost::make_shared<dem_mobility::DriverCommand>();
    resp->header = req.header;
    resp->step = req.step;
    ToMsg(c, resp.get());
    ++served_;
    return resp;
  }

  std::unique_ptr<SceneDriver> driver_;
  std::unique_ptr<ExchangeResponder<dem_mobility::DriverInput, dem_mobility::DriverCommand>> responder_;
  std::shared_ptr<Channel<dem_mobility::DriverInput, dem_mobility::DriverCommand>> failed_;  ///< held closed when the setup failed
  uint64_t served_ = 0;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::DriverNodelet, nodelet::Nodelet)
