// dem_mobility/DriverNodelet: the driver side of the lock-step exchange. Answers each DriverInput
// (speed, drive-shaft speed) with the scene driver's command (core SpeedDriver: profile, speed
// controller, clamp between the engine-brake and WOT curves, brakes).
#include <atomic>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/ros/conversions.h"

namespace dem_mobility {

class DriverNodelet : public nodelet::Nodelet {
 public:
  ~DriverNodelet() override {
    stop_ = true;
    // the vehicle learns at once that its driver is gone (instead of after its timeout)
    if (server_) server_->Leave("the driver nodelet was unloaded");
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string transport;
    try {
      const RoadSceneParams scene = LoadScene(nh);
      const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
      driver_ = std::make_unique<SceneDriver>(scene.driver, scene.vehicle_file);
      server_ = std::make_unique<ExchangeServer<DriverInput, DriverCommand>>(
          nh, transport, nh.resolveName("exchange/driver"), "exchange/driver_input", "exchange/driver_command", timing);
      NODELET_INFO("driver: %.2f m/s^2 toward %.1f m/s, every %.4g s, exchange over %s", scene.driver.accel,
                   scene.driver.v_max, scene.driver.control_period, transport.c_str());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      // in one manager, the vehicle finds the channel closed with the reason and ends the run
      // (writing its result); a standalone driver ends its process
      if (pnh.param<std::string>("exchange_transport", "shared_memory") == "shared_memory") {
        failed_ = ChannelRegistry::Get<DriverInput, DriverCommand>(nh.resolveName("exchange/driver"));
        failed_->Close(std::string("the driver could not start: ") + e.what());
      } else {
        ros::requestShutdown();
      }
      return;
    }
    thread_ = std::thread([this] { Serve(); });
  }

  void Serve() {
    uint64_t served = 0;
    long last_step = -1;
    std::string why;
    try {
      while (auto req = server_->Wait(stop_, &why)) {
        const long step = static_cast<long>(req->step);
        DM_THROW_UNLESS(step > last_step, "driver input of step ", step, " after step ", last_step,
                        ": the lock-step order is broken");
        const DriveCommand c = driver_->Exchange(FromMsg(*req));
        auto resp = boost::make_shared<DriverCommand>();
        resp->header = req->header;
        resp->step = req->step;
        ToMsg(c, resp.get());
        server_->Reply(resp);
        ++served;
        last_step = step;
      }
      NODELET_INFO("driver: %lu commands given; the exchange ended (%s)", static_cast<unsigned long>(served),
                   why.c_str());
    } catch (const std::exception& e) {
      NODELET_ERROR("driver: %s", e.what());
      server_->Leave(std::string("the driver failed: ") + e.what());
    }
  }

  std::unique_ptr<SceneDriver> driver_;
  std::unique_ptr<ExchangeServer<DriverInput, DriverCommand>> server_;
  std::shared_ptr<Channel<DriverInput, DriverCommand>> failed_;  ///< held closed when the setup failed
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::DriverNodelet, nodelet::Nodelet)
