// dem_mobility/VehicleNodelet: the vehicle side of the co-simulation and its clock. Runs the core's
// scene loop (RunCoSimulation) with the terrain and the driver reached through lock-step exchanges,
// and publishes what users watch and keep: /clock, tf (every body), odometry, the exchanged wheel
// states, wrenches and driver commands (decimated to log_rate), markers, progress, the result. The
// result YAML holds the terrain's own figures too (a DEM soil's level, table, patch checks): the
// terrain nodelet gives them through its service terrain/report once the run is over (or, when ROS
// is shutting down, as on Ctrl-C, directly within the manager's process: TerrainFiguresBoard).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <thread>

#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "dem_mobility/MobilityResult.h"
#include "dem_mobility/TerrainReport.h"
#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/mobility/cosim_loop.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/ros/conversions.h"
#include "dem_mobility/ros/vehicle_visuals.h"
#include "dem_mobility/ros/core_names.h"
#include "dem_mobility/ros/recorder_watch.h"
#include "dem_mobility/ros/terrain_figures_board.h"

namespace dem_mobility {
namespace {

/// The terrain reached through the lock-step exchange.
class ExchangeTerrainPort final : public TerrainPort {
 public:
  /// `describe`: what the terrain is, asked of it once, right after the opening exchange (by then it
  /// has read its file and is prepared); false and a reason when it cannot say.
  ExchangeTerrainPort(std::unique_ptr<ExchangeClient<WheelStates, WheelWrenches>> client, std::string frame,
                      std::function<bool(TerrainDescription*, std::string*)> describe)
      : client_(std::move(client)), frame_(std::move(frame)), describe_(std::move(describe)) {}
  const TerrainDescription& description() const override { return description_; }
  void Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                std::vector<WheelWrench>* wrenches) override {
    auto req = boost::make_shared<WheelStates>();
    req->header.stamp = ros::Time(t);
    req->header.frame_id = frame_;
    req->step = static_cast<uint64_t>(step);
    req->time_step = dt;
    ToMsg(states, req.get());
    try {
      last_resp = client_->Call(req, req->step);
      FromMsg(*last_resp, wrenches);
    } catch (const std::exception& e) {
      throw SimulationError(e.what());
    }
    last_req = req;
    if (!described_) {
      std::string why;
      if (!describe_(&description_, &why)) throw SimulationError("the terrain does not say what it is: " + why);
      described_ = true;
    }
  }
  void Leave(const std::string& why) { client_->Leave(why); }
  boost::shared_ptr<const WheelStates> last_req;
  boost::shared_ptr<const WheelWrenches> last_resp;

 private:
  std::unique_ptr<ExchangeClient<WheelStates, WheelWrenches>> client_;
  std::string frame_;
  std::function<bool(TerrainDescription*, std::string*)> describe_;
  TerrainDescription description_;  ///< the terrain nodelet's (its report), after the opening exchange
  bool described_ = false;
};

/// The driver reached through the lock-step exchange.
class ExchangeDriverPort final : public DriverPort {
 public:
  explicit ExchangeDriverPort(std::unique_ptr<ExchangeClient<dem_mobility::DriverInput, dem_mobility::DriverCommand>> client)
      : client_(std::move(client)) {}
  core::DriverCommand Exchange(const core::DriverInput& in) override {
    auto req = boost::make_shared<dem_mobility::DriverInput>();
    req->header.stamp = ros::Time(stamp_offset + in.time);
    ToMsg(in, req.get());
    try {
      last_resp = client_->Call(req, req->step);
      return FromMsg(*last_resp);
    } catch (const std::exception& e) {
      throw SimulationError(e.what());
    }
  }
  void Leave(const std::string& why) { client_->Leave(why); }
  double stamp_offset = 0.0;  ///< simulation time of the driver's start
  boost::shared_ptr<const dem_mobility::DriverCommand> last_resp;

 private:
  std::unique_ptr<ExchangeClient<dem_mobility::DriverInput, dem_mobility::DriverCommand>> client_;
};

/// A publisher that counts what it published (the bag test compares the counts).
struct Counted {
  ros::Publisher pub;
  std::string name;
  long count = 0;
  template <class M>
  void Publish(const M& m) {
    pub.publish(m);
    ++count;
  }
};

}  // namespace

class VehicleNodelet : public nodelet::Nodelet, private CoSimObserver {
 public:
  ~VehicleNodelet() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    pnh.getParam("result_file", result_file_);  // first: a bad scene is reported there too
    try {
      Param(pnh, "result_file", &result_file_);
      scene_ = LoadScene(nh);
      std::string transport;
      const ExchangeTiming timing = LoadExchangeTiming(pnh, &transport);
      Param(pnh, "world_frame", &world_frame_);
      Param(pnh, "map_frame", &map_frame_);
      Param(pnh, "base_frame", &base_frame_);
      double log_rate = 100.0, clock_rate = 100.0;
      RateParam(pnh, "log_rate", &log_rate, "every step");
      RateParam(pnh, "clock_rate", &clock_rate);
      Param(pnh, "max_real_time_factor", &max_rtf_);
      Param(pnh, "wait_for_recorder", &wait_for_recorder_);
      Param(pnh, "shutdown_when_done", &shutdown_when_done_);
      Param(pnh, "force_scale", &force_scale_);
      auto check = [&pnh](bool ok, const std::string& name, const std::string& what) {
        if (!ok) throw ConfigError("parameter " + pnh.resolveName(name) + ": " + what);
      };
      check(max_rtf_ >= 0.0 && std::isfinite(max_rtf_), "max_real_time_factor", "must be >= 0 (0: as fast as possible)");
      check(force_scale_ > 0.0 && std::isfinite(force_scale_), "force_scale", "must be a positive length per force [m/N]");
      log_rate_ = log_rate;
      clock_rate_ = clock_rate;
      ResultFile::CheckWritable(result_file_, "parameter " + pnh.resolveName("result_file"));
      sim_ = std::make_unique<VehicleCoSim>(scene_, VehicleSpec::Load(scene_.vehicle_file));
      terrain_ = std::make_unique<ExchangeTerrainPort>(
          std::make_unique<ExchangeClient<WheelStates, WheelWrenches>>(
              nh, transport, nh.resolveName("exchange/terrain"), "exchange/wheel_states", "exchange/wheel_wrenches",
              "terrain", timing),
          world_frame_, [this](TerrainDescription* d, std::string* why) { return TerrainDescriptionOf(d, why); });
      driver_ = std::make_unique<ExchangeDriverPort>(std::make_unique<ExchangeClient<dem_mobility::DriverInput, dem_mobility::DriverCommand>>(
          nh, transport, nh.resolveName("exchange/driver"), "exchange/driver_input", "exchange/driver_command", "driver",
          timing));
      NODELET_INFO("vehicle '%s' (%d bodies) on %s, grade %.2f deg, exchange over %s",
                   sim_->vehicle().name().c_str(), sim_->vehicle().system().num_bodies() - 1, scene_.file.c_str(),
                   scene_.grade_deg, transport.c_str());
      NODELET_INFO("terrain from %s: waiting up to %.0f s for it to be ready (a DEM soil is prepared first)",
                   scene_.terrain_file.c_str(), timing.startup_timeout);
    } catch (const std::exception& e) {
      Fail(std::string(e.what()));
      return;
    }
    Advertise(nh);
    // the bag recorder's failure (a full disk, a file size limit) ends the run with its error
    recorder_.Start(nh);
    thread_ = std::thread([this] { Run(); });
  }

  void Advertise(ros::NodeHandle& nh) {
    auto add = [this](Counted* c, ros::Publisher p, const std::string& name) {
      c->pub = p;
      c->name = name;
      counted_.push_back(c);
    };
    // queues large enough that a burst to a slow remote subscriber is not dropped
    const uint32_t q = 10000;
    ros::NodeHandle root;
    add(&clock_, root.advertise<rosgraph_msgs::Clock>("/clock", 10), "clock");
    add(&tf_, root.advertise<tf2_msgs::TFMessage>("/tf", q), "tf");
    add(&tf_static_, root.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true), "tf_static");
    add(&odom_, nh.advertise<nav_msgs::Odometry>("odom", q), "odom");
    add(&states_, nh.advertise<WheelStates>("wheel_states", q), "wheel_states");
    add(&wrenches_, nh.advertise<WheelWrenches>("wheel_wrenches", q), "wheel_wrenches");
    add(&command_, nh.advertise<dem_mobility::DriverCommand>("driver_command", q), "driver_command");
    add(&body_markers_, nh.advertise<visualization_msgs::MarkerArray>("vehicle/markers", q, true), "vehicle/markers");
    add(&live_markers_, nh.advertise<visualization_msgs::MarkerArray>("vehicle/forces", q), "vehicle/forces");
    add(&result_, nh.advertise<MobilityResult>("result", 1, true), "result");
  }

  /// Waits until every logged topic has a subscriber (the recorder), so nothing is lost at the start.
  void WaitForRecorder() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    for (;;) {
      bool all = true;
      for (const Counted* c : counted_)
        if (c != &clock_ && c->pub.getNumSubscribers() == 0) all = false;
      if (all) return;
      if (std::chrono::steady_clock::now() > end)
        throw ConfigError("no recorder subscribed to the logged topics within 60 s (set ~wait_for_recorder false "
                          "to run without one)");
      if (recorder_.failed()) throw ConfigError(recorder_.error());
      if (stop_ || !ros::ok()) throw ConfigError("stopped while waiting for the recorder");
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  void Run() {
    MobilityRunResult r;
    try {
      if (wait_for_recorder_) WaitForRecorder();
      PublishStatic();
      sim_->Start(*terrain_);
      const double dt = sim_->dt();
      log_every_ = log_rate_ > 0.0 ? std::max(1L, std::lround(1.0 / (log_rate_ * dt))) : 1;
      clock_every_ = std::max(1L, std::lround(1.0 / (clock_rate_ * dt)));
      // the driver's start: the first step after the settling steps (settle_time / dt rounded),
      // so that a command's stamp is the time of the step it was computed at
      driver_->stamp_offset = sim_->settle_steps() * dt;
      // the coupling in use: with a terrain of its own step (a DEM soil) and time_step auto, the
      // vehicle steps that fit in one terrain step times the scene's coupling_interval
      NODELET_INFO("time step %.4g s (critical %.4g s: %s), coupling every %d step(s) (%.4g s; scene's "
                   "coupling_interval %d), logging every %ld step(s), %.1f s of driving after %.2f s of settling",
                   dt, sim_->limit().dt_crit, sim_->limit().element.c_str(), sim_->coupling_interval(),
                   dt * sim_->coupling_interval(), scene_.coupling_interval, log_every_, scene_.duration,
                   scene_.settle_time);
      wall0_ = std::chrono::steady_clock::now();
      r = RunCoSimulation(*sim_, *terrain_, *driver_, this);
      if (recorder_.failed()) {  // the loop stopped for it: an error, not an interruption
        r.interrupted = false;
        r.error = recorder_.error();
      } else if (!r.error.empty() && ShuttingDown()) {
        // a peer gone in a shutdown (roslaunch stops the nodelet loaders first, and each unloads
        // its nodelet): the run was interrupted, the peer's leaving is its reason
        r.interrupted = true;
        interrupted_why_ = r.error;
        r.error.clear();
      }
    } catch (const std::exception& e) {  // configuration errors (time step) before the first step
      if (recorder_.failed()) {
        r.error = recorder_.error();
      } else if (ShuttingDown()) {
        // a shutdown before the run began (e.g. while the soil was being prepared): interrupted,
        // with the reason the exchange gave
        r.interrupted = true;
        interrupted_why_ = e.what();
        std::string why;
        TerrainDescriptionOf(&r.terrain, &why);  // (what the terrain had read, if it had)
      } else {
        r.error = e.what();
      }
    }
    const std::string why = !r.error.empty() ? "the vehicle stopped: " + r.error : "the vehicle finished";
    terrain_->Leave(why);
    driver_->Leave(why);
    Finish(r);
  }

  // --- CoSimObserver
  void OnStep(const VehicleCoSim& sim, const core::DriverCommand& /*cmd*/) override {
    const long k = sim.step();
    if (k % clock_every_ == 0) {
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(sim.time());
      clock_.Publish(c);
      Pace(sim.time());
    }
    if (k % log_every_ == 0) Log(sim);
    if ((k & 255) == 0) Progress(sim);
  }
  bool StopRequested() override { return stop_.load() || recorder_.failed() || !ros::ok(); }

  /// True when this nodelet or the process is being shut down, or is within `grace` seconds (a
  /// peer that left may have left for a shutdown that reaches this nodelet moments later).
  bool ShuttingDown(double grace = 1.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace);
    for (;;) {
      if (stop_ || !ros::ok()) return true;
      if (std::chrono::steady_clock::now() >= end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  void Pace(double t_sim) {
    if (max_rtf_ <= 0.0) return;
    const auto due = wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(t_sim / max_rtf_));
    std::this_thread::sleep_until(due);
  }

  void Progress(const VehicleCoSim& sim) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
    if (wall < next_progress_) return;
    next_progress_ += 1.0;
    const double t = std::max(0.0, sim.driver_time()), rtf = sim.time() / wall;
    NODELET_INFO("t = %6.2f / %.4g s  speed %6.2f m/s  real-time factor %.2f  ETA %.0f s", t, scene_.duration,
                 sim.vehicle().ForwardSpeed(), rtf, (scene_.duration - t) / std::max(rtf, 1e-9));
  }

  void Log(const VehicleCoSim& sim) {
    const ros::Time stamp(sim.time());
    const Vehicle& v = sim.vehicle();
    // the exchanged messages themselves (zero copy); the latest ones when the coupling skips steps
    if (terrain_->last_req && terrain_->last_req != logged_req_) {
      states_.Publish(terrain_->last_req);
      wrenches_.Publish(terrain_->last_resp);
      logged_req_ = terrain_->last_req;
    }
    if (driver_->last_resp && driver_->last_resp != logged_cmd_) {
      command_.Publish(driver_->last_resp);
      logged_cmd_ = driver_->last_resp;
    }
    tf_.Publish(BodyTransforms(v, stamp, world_frame_, base_frame_));
    odom_.Publish(ChassisOdometry(v, stamp, world_frame_, base_frame_));
    live_markers_.Publish(LiveMarkers(sim, stamp, world_frame_, force_scale_));
    if (sim.time() >= next_body_markers_) {  // frame-locked body shapes: once a simulated second
      body_markers_.Publish(BodyMarkers(v, stamp, base_frame_));
      next_body_markers_ += 1.0;
    }
  }

  void PublishStatic() {
    tf2_msgs::TFMessage m;
    m.transforms.push_back(SlopeTransform(scene_.Gravity(), ros::Time(0), map_frame_, world_frame_));
    tf_static_.Publish(m);
  }

  void Finish(const MobilityRunResult& r) {
    // the terrain's figures first: its state is final now (the last exchange has been answered)
    std::string report_error;
    const YAML::Node terrain = TerrainFigures(&report_error);
    MobilityResult m;
    m.header.stamp = ros::Time(sim_ ? sim_->time() : 0.0);
    m.header.frame_id = world_frame_;
    m.scene = scene_.file;
    m.kind = scene_.kind;
    m.grade_deg = scene_.grade_deg;
    m.cone_index_psi = r.terrain.cone_index;
    m.terrain_model = r.terrain.model;
    m.fidelity = r.terrain.fidelity;
    // the level's error estimate, as the terrain reports it in the result file: a number, or a
    // text saying it was not measured
    m.speed_error_estimate = std::numeric_limits<double>::quiet_NaN();
    if (const YAML::Node e = terrain["speed_error_estimate"]) {
      double v = 0.0;
      if (YAML::convert<double>::decode(e, v))
        m.speed_error_estimate = v;
      else
        m.speed_error_note = e.as<std::string>();
    }
    if (const YAML::Node n = terrain["speed_error_note"]) m.speed_error_note = n.as<std::string>();
    m.speed_made_good = r.smg.value;
    m.speed_made_good_mph = r.smg.value / 0.44704;
    m.status = r.Status();
    m.window_slope = r.smg.window_slope;
    m.window_speed_std = r.smg.window_std;
    m.window_end_slope = r.smg.end_slope;
    m.window_samples = static_cast<uint32_t>(r.steady.samples);
    m.slip.assign(r.steady.slip.begin(), r.steady.slip.end());
    m.sinkage.assign(r.steady.sinkage.begin(), r.steady.sinkage.end());
    m.traction_coefficient = r.steady.traction_coefficient;
    m.motion_resistance_coefficient = r.steady.motion_resistance;
    m.drawbar_margin = r.steady.drawbar_margin;
    m.time_step = r.dt;
    m.terrain_time_step = r.terrain.time_step;
    m.critical_time_step = r.dt_crit;
    m.critical_element = r.dt_limit_element;
    m.coupling_interval = static_cast<uint32_t>(r.coupling_interval);
    m.steps = static_cast<uint64_t>(r.steps);
    m.exchanges = static_cast<uint64_t>(r.exchanges);
    m.simulated_time = r.sim_time;
    m.wall_time = r.wall_time;
    m.real_time_factor = r.wall_time > 0.0 ? r.sim_time / r.wall_time : 0.0;  // as in the result YAML
    m.error = r.error.empty() ? interrupted_why_ : r.error;
    result_.Publish(m);
    if (!r.error.empty()) NODELET_ERROR("run failed: %s", r.error.c_str());
    NODELET_INFO("speed_made_good: %.3f m/s (%.2f mph), status %s; %ld steps, %.2f s driven in %.2f s wall",
                 r.smg.value, r.smg.value / 0.44704, m.status.c_str(), r.steps, r.sim_time, r.wall_time);
    if (!result_file_.empty()) {
      std::vector<std::pair<std::string, long>> counts;
      for (const Counted* c : counted_) counts.emplace_back(c->name, c->count);
      try {
        // as the in-process runner writes it (MobilityResultFile with the terrain model): the
        // terrain's figures after the run's, in the terrain's order
        ResultFile f = MobilityResultFile(r, scene_, counts);
        if (r.Status() == "interrupted" && !interrupted_why_.empty()) f.SetStatus("interrupted", interrupted_why_);
        for (const auto& kv : terrain) f.Set(kv.first.as<std::string>(), kv.second);
        if (!report_error.empty()) f.Set("terrain_report", "missing: " + report_error);
        f.Write(result_file_);
        NODELET_INFO("result: %s", result_file_.c_str());
      } catch (const std::exception& e) {
        NODELET_ERROR("%s", e.what());
      }
    }
    if (shutdown_when_done_) ros::requestShutdown();
  }

  /// The terrain's own figures (a YAML map; empty when it has none or could not give them: then
  /// `error` says why), from the terrain nodelet's service terrain/report; when that cannot answer
  /// (ROS shutting down on Ctrl-C, the terrain unloaded), from the terrain nodelet in this process
  /// (TerrainFiguresBoard: its figures now, or those of its last exchange once it has unloaded).
  YAML::Node TerrainFigures(std::string* error) {
    TerrainReport srv;
    const std::string service = AskTerrainReport(&srv.response, error);
    if (!error->empty()) {
      NODELET_WARN("the result goes without the terrain's own figures: %s", error->c_str());
      return YAML::Node(YAML::NodeType::Map);
    }
    if (!srv.response.error.empty()) {
      *error = srv.response.error;
    } else {
      try {
        const YAML::Node n = YAML::Load(srv.response.figures);
        if (n.IsMap()) return n;
        *error = service + " answered no map of figures";
      } catch (const YAML::Exception& e) {
        *error = service + " answered malformed YAML: " + e.what();
      }
    }
    NODELET_WARN("the result goes without the terrain's own figures: %s", error->c_str());
    return YAML::Node(YAML::NodeType::Map);
  }

  /// What the terrain is (its description), from its report: false and `why` when it cannot say
  /// (no answer, or it has not read its file yet).
  bool TerrainDescriptionOf(TerrainDescription* d, std::string* why) {
    TerrainReport srv;
    AskTerrainReport(&srv.response, why);
    if (why->empty() && srv.response.model.empty())
      *why = srv.response.error.empty() ? "its report names no model" : srv.response.error;
    if (!why->empty()) return false;
    d->model = srv.response.model;
    d->file = srv.response.file;
    d->cone_index = srv.response.cone_index_psi;
    d->time_step = srv.response.time_step;
    d->fidelity = srv.response.fidelity;
    return true;
  }

  /// The terrain nodelet's report, from its service terrain/report, or, when that cannot answer,
  /// from TerrainFiguresBoard (see TerrainFigures); `unanswered` says why there is none. Returns
  /// the service's name.
  std::string AskTerrainReport(TerrainReport::Response* response, std::string* unanswered) {
    ros::ServiceClient client = getNodeHandle().serviceClient<TerrainReport>("terrain/report");
    TerrainReport srv;
    std::string why;
    // the terrain nodelet advertises it when it loads; one that is gone (unloaded, killed) is not
    // waited for long
    if (!ros::ok())
      why = "ROS is shutting down";
    else if (!client.waitForExistence(ros::Duration(2.0)))
      why = "no terrain answers " + client.getService();
    else if (!client.call(srv))
      why = client.getService() + " failed";
    if (!why.empty()) {
      if (!TerrainFiguresBoard::Read(client.getService(), &srv.response)) {
        *unanswered = why;
        return client.getService();
      }
      NODELET_INFO("the terrain's report (t = %.6g s) from the terrain nodelet in this process: %s",
                   srv.response.time, why.c_str());
    }
    unanswered->clear();
    *response = srv.response;
    return client.getService();
  }

  /// A setup error: said clearly, written to the result file when one is set, and the run ends.
  void Fail(const std::string& what) {
    NODELET_FATAL("%s", what.c_str());
    if (!result_file_.empty()) {
      std::string file = scene_.file, kind = scene_.kind;
      if (file.empty()) {  // the scene did not load: its file and kind, if it reads as YAML
        try {
          const YamlReader y = LoadSceneFile(getNodeHandle());
          file = y.file();
          kind = y.String("scene");
        } catch (const std::exception&) {
        }
      }
      ResultFile r(file, kind);
      r.SetStatus("error", what);
      try {
        r.Write(result_file_);
      } catch (const std::exception& e) {
        NODELET_ERROR("%s", e.what());
      }
    }
    ros::requestShutdown();
  }

  MobilityRunParams scene_;
  std::unique_ptr<VehicleCoSim> sim_;
  std::unique_ptr<ExchangeTerrainPort> terrain_;
  std::unique_ptr<ExchangeDriverPort> driver_;
  std::string world_frame_ = "odom", map_frame_ = "map", base_frame_ = "base_link", result_file_;
  std::string interrupted_why_;  ///< why a run was interrupted before it began (the exchange's reason)
  RecorderWatch recorder_;  ///< the bag recorder's failure ends the run with its error
  double log_rate_ = 100.0, clock_rate_ = 100.0, max_rtf_ = 0.0, force_scale_ = 1e-4;
  bool wait_for_recorder_ = true, shutdown_when_done_ = false;
  long log_every_ = 1, clock_every_ = 1;
  double next_progress_ = 1.0, next_body_markers_ = 0.0;
  std::chrono::steady_clock::time_point wall0_;
  Counted clock_, tf_, tf_static_, odom_, states_, wrenches_, command_, body_markers_, live_markers_, result_;
  std::vector<Counted*> counted_;
  boost::shared_ptr<const WheelStates> logged_req_;
  boost::shared_ptr<const dem_mobility::DriverCommand> logged_cmd_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::VehicleNodelet, nodelet::Nodelet)
