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
    if (served_ > 0) NODELET_INFO("driver: %lu commands given", static_cast<unsigned long>(served_));
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
      if (pnh.param<std::string>("exchange_transport", "inline") != "topics") {
        failed_ = ChannelRegistry::Get<DriverInput, DriverCommand>(nh.resolveName("exchange/driver"));
        failed_->Close(std::string("the driver could not start: ") + e.what());
      } else {
        ros::requestShutdown();
      }
      return;
    }
    if (!server_->ServeInline([this](const DriverInput::ConstPtr& req) { return AnswerInline(req); }))
      thread_ = std::thread([this] { Serve(); });
  }

  /// The driver's command for one control step.
  DriverCommand::ConstPtr Answer(const DriverInput& req) {
    const long step = static_cast<long>(req.step);
    DM_THROW_UNLESS(step > last_step_, "driver input of step ", step, " after step ", last_step_,
                    ": the lock-step order is broken");
    const DriveCommand c = driver_->Exchange(FromMsg(req));
    auto resp = boost::make_shared<DriverCommand>();
    resp->header = req.header;
    resp->step = req.step;
    ToMsg(c, resp.get());
    ++served_;
    last_step_ = step;
    return resp;
  }

  DriverCommand::ConstPtr AnswerInline(const DriverInput::ConstPtr& req) {
    try {
      return Answer(*req);
    } catch (const std::exception& e) {
      NODELET_ERROR("driver: %s", e.what());
      server_->LeaveFromHandler(std::string("the driver failed: ") + e.what());
      return nullptr;
    }
  }

  void Serve() {
    std::string why;
    try {
      while (auto req = server_->Wait(stop_, &why)) server_->Reply(Answer(*req));
      NODELET_INFO("driver: %lu commands given; the exchange ended (%s)", static_cast<unsigned long>(served_),
                   why.c_str());
    } catch (const std::exception& e) {
      NODELET_ERROR("driver: %s", e.what());
      server_->Leave(std::string("the driver failed: ") + e.what());
    }
  }

  std::unique_ptr<SceneDriver> driver_;
  std::unique_ptr<ExchangeServer<DriverInput, DriverCommand>> server_;
  std::shared_ptr<Channel<DriverInput, DriverCommand>> failed_;  ///< held closed when the setup failed
  uint64_t served_ = 0;
  long last_step_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::DriverNodelet, nodelet::Nodelet)
