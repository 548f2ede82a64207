// dem_mobility/ExchangeBenchNodelet: the cosim_exchange benchmark. Two of them (role client and
// server) do the vehicle-terrain exchange with the real messages (4 wheel states one way, 4 wheel
// wrenches the other) through the same ExchangeClient/ExchangeServer the vehicle and terrain
// nodelets use, with no physics in between, so what is timed is the exchange alone. The client
// times every round trip and writes the median and the 99th percentile to ~out (YAML).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

class ExchangeBenchNodelet : public nodelet::Nodelet {
 public:
  ~ExchangeBenchNodelet() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::string role, transport;
    pnh.param<std::string>("role", role, "");
    pnh.param("round_trips", round_trips_, 200000);
    pnh.param("warmup", warmup_, 20000);
    pnh.param<std::string>("out", out_, "");
    pnh.param<std::string>("label", label_, "");
    const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
    spin_ = timing.spin;
    transport_ = transport;
    if (role == "client") {
      client_ = std::make_unique<ExchangeClient<WheelStates, WheelWrenches>>(
          nh, transport, nh.resolveName("exchange/terrain"), "exchange/wheel_states", "exchange/wheel_wrenches",
          "bench server", timing);
      thread_ = std::thread([this] { Client(); });
    } else if (role == "server") {
      server_ = std::make_unique<ExchangeResponder<WheelStates, WheelWrenches>>(
          std::make_unique<ExchangeServer<WheelStates, WheelWrenches>>(nh, transport, nh.resolveName("exchange/terrain"),
                                                                       "exchange/wheel_states",
                                                                       "exchange/wheel_wrenches", timing),
          "bench server", [this](const WheelStates& req) { return Answer(req); },
          [this](const std::string& m) { NODELET_ERROR("%s", m.c_str()); }, [](const std::string&) {});
    } else {
      NODELET_FATAL("parameter %s must be client or server", pnh.resolveName("role").c_str());
      ros::requestShutdown();
    }
  }

  void Client() {
    std::vector<WheelState> states(4);
    std::vector<double> us;
    us.reserve(round_trips_);
    try {
      for (int i = 0; i < warmup_ + round_trips_ && !stop_; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        auto req = boost::make_shared<WheelStates>();
        req->step = static_cast<uint64_t>(i);
        req->header.stamp = ros::Time(1e-4 * (i + 1));
        ToMsg(states, req.get());
        auto resp = client_->Call(req, req->step);
        const auto t1 = std::chrono::steady_clock::now();
        if (i >= warmup_) us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      }
    } catch (const std::exception& e) {
      NODELET_ERROR("cosim_exchange: %s", e.what());
    }
    client_->Leave("the benchmark finished");
    if (!us.empty()) {
      std::sort(us.begin(), us.end());
      const double median = us[us.size() / 2], p99 = us[static_cast<size_t>(0.99 * (us.size() - 1))];
      NODELET_INFO("cosim_exchange %s: %zu round trips, median %.2f us, p99 %.2f us", label_.c_str(), us.size(), median,
                   p99);
      if (!out_.empty()) {
        std::ofstream f(out_);
        f << "label: " << label_ << "\ntransport: " << transport_ << "\nspin_s: " << spin_
          << "\nround_trips: " << us.size() << "\nmedian_us: " << median << "\np99_us: " << p99 << "\n";
      }
    }
    ros::requestShutdown();
  }

  WheelWrenches::ConstPtr Answer(const WheelStates& req) {
    auto resp = boost::make_shared<WheelWrenches>();
    resp->header = req.header;
    resp->step = req.step;
    resp->served = ++served_;
    ToMsg(wrenches_, resp.get());
    return resp;
  }

  std::unique_ptr<ExchangeClient<WheelStates, WheelWrenches>> client_;
  std::unique_ptr<ExchangeResponder<WheelStates, WheelWrenches>> server_;
  std::vector<WheelWrench> wrenches_ = std::vector<WheelWrench>(4);
  uint64_t served_ = 0;
  int round_trips_ = 0, warmup_ = 0;
  double spin_ = 0.0;
  std::string out_, label_, transport_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::ExchangeBenchNodelet, nodelet::Nodelet)
