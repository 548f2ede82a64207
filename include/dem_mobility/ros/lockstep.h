// The lock-step exchange between nodelets: a request/response pair of messages per step.
//
// Three transports behind one interface:
//  - "inline" (the default in one manager): both nodelets meet in a named Channel; the answering
//    nodelet registers its handler there and the asking nodelet's thread runs it, so a step never
//    changes threads: no hand-off, no spinning, and the other cores stay free (the bag recorder,
//    rviz, the soil's OpenMP threads). The messages are the same zero-copy shared pointers.
//  - "shared_memory": both nodelets in one manager (one process) meet in a named Channel; messages
//    pass as shared pointers (zero copy) through single-slot mailboxes. A waiting side spins for a
//    short time (the peer's step is usually shorter than a thread wake-up) and then blocks on a
//    condition variable, so it costs a core only while it spins.
//  - "topics": the peers are separate processes (`nodelet standalone`, for debugging); requests and
//    responses travel on ROS topics and land in the same mailboxes.
// Either side may leave (nodelet unloaded, process killed): the other gets a clear error, never a
// hang, because every wait has a deadline and a left peer closes the channel.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include <boost/shared_ptr.hpp>
#include <ros/ros.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DM_CPU_RELAX() _mm_pause()
#else
#define DM_CPU_RELAX() ((void)0)
#endif

namespace dem_mobility {

/// A peer left, did not answer in time, or answered out of order.
class ExchangeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A single-slot mailbox: Put replaces the slot and wakes the taker; Take waits for a message newer
/// than the last one taken. One putter and one taker.
template <class M>
class Mailbox {
 public:
  using Ptr = boost::shared_ptr<const M>;
  enum class Wait { kMessage, kTimeout, kClosed };

  void Put(const Ptr& m) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      slot_ = m;
      seq_.fetch_add(1);
    }
    if (sleepers_.load() > 0) cv_.notify_one();
  }
  /// Waits up to `timeout` for a new message: spins for up to `spin`, then blocks.
  Wait Take(std::chrono::nanoseconds spin, std::chrono::nanoseconds timeout, Ptr* out) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!Ready()) {
      const auto spin_end = t0 + spin;
      int n = 0;
      while (!Ready() && !closed_.load(std::memory_order_acquire)) {
        DM_CPU_RELAX();
        if ((++n & 63) == 0 && std::chrono::steady_clock::now() >= spin_end) break;
      }
    }
    std::unique_lock<std::mutex> lock(mutex_);
    if (!Ready() && !closed_.load()) {
      sleepers_.fetch_add(1);
      cv_.wait_until(lock, t0 + timeout, [this] { return Ready() || closed_.load(); });
      sleepers_.fetch_sub(1);
    }
    if (!Ready()) return closed_.load() ? Wait::kClosed : Wait::kTimeout;
    taken_ = seq_.load();
    *out = slot_;
    return Wait::kMessage;
  }
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_.store(true);
    }
    cv_.notify_all();
  }
  bool closed() const { return closed_.load(); }

 private:
  bool Ready() const { return seq_.load(std::memory_order_acquire) != taken_; }
  std::mutex mutex_;
  std::condition_variable cv_;
  std::atomic<uint64_t> seq_{0};
  uint64_t taken_ = 0;  ///< only the taker touches it
  std::atomic<int> sleepers_{0};
  std::atomic<bool> closed_{false};
  Ptr slot_;
};

/// Timing of a side's waits (seconds).
struct ExchangeTiming {
  double spin = 50e-6;          ///< spin before blocking
  double peer_timeout = 10.0;   ///< longest wait for an answer once running
  double startup_timeout = 60.0;///< longest wait for the first answer (the peer may still be loading)
};

/// The meeting point of two nodelets of one process: requests one way, responses the other.
template <class Req, class Resp>
struct Channel {
  using Handler = std::function<boost::shared_ptr<const Resp>(const boost::shared_ptr<const Req>&)>;
  Mailbox<Req> requests;
  Mailbox<Resp> responses;
  std::mutex mutex;
  std::string closed_by;  ///< who closed it and why
  /// inline transport: the answering side's handler, run under handler_mutex (so that a side
  /// leaving waits for a call in progress and no call starts after it left)
  std::mutex handler_mutex;
  Handler handler;
  void Close(const std::string& why) {
    CloseFromHandler(why);
    std::lock_guard<std::mutex> lock(handler_mutex);
    handler = nullptr;
  }
  std::string why() {
    std::lock_guard<std::mutex> lock(mutex);
    return closed_by;
  }
  /// Closes the channel from inside an inline handler (which holds handler_mutex).
  void CloseFromHandler(const std::string& why) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (closed_by.empty()) closed_by = why;
    }
    requests.Close();
    responses.Close();
  }
};

/// Process-wide registry of channels by name (the resolved exchange namespace). A channel lives
/// while either side holds it (closed or not: a peer that failed to start holds its channel closed,
/// with the reason, for the other side to find); once neither does, the name gets a fresh one.
class ChannelRegistry {
 public:
  template <class Req, class Resp>
  static std::shared_ptr<Channel<Req, Resp>> Get(const std::string& name) {
    static std::mutex mutex;
    static std::map<std::string, std::weak_ptr<void>> channels;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = channels.find(name);
    if (it != channels.end()) {
      if (auto p = std::static_pointer_cast<Channel<Req, Resp>>(it->second.lock())) return p;
    }
    auto p = std::make_shared<Channel<Req, Resp>>();
    channels[name] = p;
    return p;
  }
};

inline std::chrono::nanoseconds Seconds(double s) {
  return std::chrono::nanoseconds(static_cast<int64_t>(s * 1e9));
}

/// The asking side (the vehicle): one Call per exchange.
template <class Req, class Resp>
class ExchangeClient {
 public:
  using ReqPtr = boost::shared_ptr<const Req>;
  using RespPtr = boost::shared_ptr<const Resp>;
  /// `transport`: "shared_memory" or "topics"; `name`: the exchange (topic namespace, resolved);
  /// `peer`: how errors call the other side ("terrain").
  ExchangeClient(ros::NodeHandle nh, const std::string& transport, const std::string& name,
                 const std::string& req_topic, const std::string& resp_topic, const std::string& peer,
                 const ExchangeTiming& timing)
      : peer_(peer), timing_(timing), inline_(transport == "inline") {
    if (transport == "shared_memory" || transport == "inline") {
      channel_ = ChannelRegistry::Get<Req, Resp>(name);
    } else if (transport == "topics") {
      own_ = std::make_shared<Channel<Req, Resp>>();
      pub_ = nh.advertise<Req>(req_topic, 1);
      auto ch = own_;
      sub_ = nh.subscribe<Resp>(resp_topic, 1, [ch](const RespPtr& m) { ch->responses.Put(m); },
                                ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    } else {
      throw std::invalid_argument("exchange transport '" + transport + "': use inline, shared_memory or topics");
    }
  }
  ~ExchangeClient() { Leave("the " + peer_ + "'s client left"); }

  /// Sends `req` (step `step`) and waits for the answer to it.
  RespPtr Call(const ReqPtr& req, uint64_t step) {
    if (inline_) return CallInline(req, step);
    Channel<Req, Resp>& ch = channel_ ? *channel_ : *own_;
    if (channel_) {
      ch.requests.Put(req);
    } else {
      if (first_) WaitForSubscriber();
      pub_.publish(req);
    }
    const double timeout = first_ ? timing_.startup_timeout : timing_.peer_timeout;
    RespPtr resp;
    // in slices of at most 0.25 s, so that a shutdown (SIGINT) ends a long wait (the first answer
    // of a soil still being prepared) at once; an answer ends a slice as soon as it is there, and
    // the usual exchange (answered in the first slice) reads no clock
    const std::chrono::nanoseconds whole = Seconds(timeout), slice = std::min(whole, Seconds(0.25));
    std::chrono::nanoseconds waited = slice;
    typename Mailbox<Resp>::Wait w = ch.responses.Take(Seconds(timing_.spin), slice, &resp);
    while (w == Mailbox<Resp>::Wait::kTimeout && waited < whole) {
      if (!ros::ok())
        throw ExchangeError("shut down while waiting for the " + peer_ + "'s answer to step " + std::to_string(step));
      const std::chrono::nanoseconds next = std::min(slice, whole - waited);
      w = ch.responses.Take(Seconds(timing_.spin), next, &resp);
      waited += next;
    }
    if (w == Mailbox<Resp>::Wait::kClosed)
      throw ExchangeError("the " + peer_ + " left the exchange at step " + std::to_string(step) + " (" + ch.why() + ")");
    if (w == Mailbox<Resp>::Wait::kTimeout)
      throw ExchangeError("the " + peer_ + " did not answer step " + std::to_string(step) + " within " +
                          std::to_string(timeout) + " s (is its nodelet loaded and alive?)");
    if (resp->step != step)
      throw ExchangeError("the " + peer_ + " answered step " + std::to_string(resp->step) + " to step " +
                          std::to_string(step) + ": the lock-step order is broken");
    first_ = false;
    return resp;
  }
  /// Leaves the exchange (the peer's waits end at once).
  void Leave(const std::string& why) {
    if (channel_) channel_->Close(why);
  }

 private:
  RespPtr CallInline(const ReqPtr& req, uint64_t step) {
    Channel<Req, Resp>& ch = *channel_;
    const auto end = std::chrono::steady_clock::now() + Seconds(first_ ? timing_.startup_timeout : timing_.peer_timeout);
    RespPtr resp;
    for (;;) {
      bool closed = false;
      {
        std::lock_guard<std::mutex> lock(ch.handler_mutex);
        closed = ch.requests.closed();
        if (!closed && ch.handler) {
          resp = ch.handler(req);
          break;
        }
      }
      if (closed)
        throw ExchangeError("the " + peer_ + " left the exchange at step " + std::to_string(step) + " (" + ch.why() +
                            ")");
      if (!ros::ok()) {
        // a shutdown: the peer, stopped by it too (a soil's preparation), closes the exchange with
        // its reason within moments; that reason says more than ours
        const auto grace = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
        while (!ch.requests.closed() && std::chrono::steady_clock::now() < grace)
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        if (ch.requests.closed())
          throw ExchangeError("shut down while waiting for the " + peer_ + "'s answer to step " + std::to_string(step) +
                              ": " + ch.why());
        throw ExchangeError("shut down while waiting for the " + peer_ + "'s answer to step " + std::to_string(step));
      }
      if (std::chrono::steady_clock::now() > end)
        throw ExchangeError("the " + peer_ + " did not answer step " + std::to_string(step) +
                            " (is its nodelet loaded in this manager?)");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));  // not there yet (still loading)
    }
    if (!resp)
      throw ExchangeError("the " + peer_ + " could not answer step " + std::to_string(step) + " (" + ch.why() + ")");
    if (resp->step != step)
      throw ExchangeError("the " + peer_ + " answered step " + std::to_string(resp->step) + " to step " +
                          std::to_string(step) + ": the lock-step order is broken");
    first_ = false;
    return resp;
  }

  void WaitForSubscriber() {
    const auto end = std::chrono::steady_clock::now() + Seconds(timing_.startup_timeout);
    while (pub_.getNumSubscribers() == 0 || sub_.getNumPublishers() == 0) {
      if (!ros::ok())
        throw ExchangeError("shut down while waiting for the " + peer_ + " on topic " + pub_.getTopic());
      if (std::chrono::steady_clock::now() > end)
        throw ExchangeError("no " + peer_ + " on topic " + pub_.getTopic() + " within " +
                            std::to_string(timing_.startup_timeout) + " s");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  std::string peer_;
  ExchangeTiming timing_;
  bool inline_ = false;
  std::shared_ptr<Channel<Req, Resp>> channel_, own_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
  bool first_ = true;
};

/// The answering side (terrain, driver): Wait for a request, Reply to it.
template <class Req, class Resp>
class ExchangeServer {
 public:
  using ReqPtr = boost::shared_ptr<const Req>;
  using RespPtr = boost::shared_ptr<const Resp>;
  ExchangeServer(ros::NodeHandle nh, const std::string& transport, const std::string& name,
                 const std::string& req_topic, const std::string& resp_topic, const ExchangeTiming& timing)
      : timing_(timing), inline_(transport == "inline") {
    if (transport == "shared_memory" || transport == "inline") {
      channel_ = ChannelRegistry::Get<Req, Resp>(name);
    } else if (transport == "topics") {
      own_ = std::make_shared<Channel<Req, Resp>>();
      pub_ = nh.advertise<Resp>(resp_topic, 1);
      auto ch = own_;
      sub_ = nh.subscribe<Req>(req_topic, 1, [ch](const ReqPtr& m) { ch->requests.Put(m); }, ros::VoidConstPtr(),
                               ros::TransportHints().tcpNoDelay());
    } else {
      throw std::invalid_argument("exchange transport '" + transport + "': use inline, shared_memory or topics");
    }
  }
  ~ExchangeServer() { Leave("the server left"); }

  /// With the inline transport the client's thread runs `handler` for every request (a null
  /// answer means the handler failed and left the exchange); returns false for other transports,
  /// whose requests come through Wait.
  /// Leaves from inside the inline handler.
  void LeaveFromHandler(const std::string& why) {
    if (channel_) channel_->CloseFromHandler(why);
  }
  bool ServeInline(typename Channel<Req, Resp>::Handler handler) {
    if (!inline_) return false;
    std::lock_guard<std::mutex> lock(channel_->handler_mutex);
    if (!channel_->requests.closed()) channel_->handler = std::move(handler);
    return true;
  }
  /// The next request, or null when the client left (`why` tells) or `stop` was set.
  ReqPtr Wait(const std::atomic<bool>& stop, std::string* why) {
    Channel<Req, Resp>& ch = channel_ ? *channel_ : *own_;
    ReqPtr req;
    for (;;) {
      if (stop.load()) {
        *why = "stopped";
        return nullptr;
      }
      switch (ch.requests.Take(Seconds(timing_.spin), std::chrono::milliseconds(100), &req)) {
        case Mailbox<Req>::Wait::kMessage:
          return req;
        case Mailbox<Req>::Wait::kClosed:
          *why = ch.why();
          return nullptr;
        case Mailbox<Req>::Wait::kTimeout:
          if (stop.load() || !ros::ok()) {
            *why = "stopped";
            return nullptr;
          }
      }
    }
  }
  void Reply(const RespPtr& resp) {
    if (channel_) channel_->responses.Put(resp);
    else pub_.publish(resp);
  }
  void Leave(const std::string& why) {
    if (channel_) channel_->Close(why);
  }

 private:
  ExchangeTiming timing_;
  bool inline_ = false;
  std::shared_ptr<Channel<Req, Resp>> channel_, own_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
};

/// The answering nodelet's side of an exchange, whatever the transport: `answer` turns a request
/// into its response (and throws when it cannot). Inline, the client's thread runs it; otherwise a
/// thread of its own waits for requests. Every request must be newer than the last (the lock-step
/// order); a failing answer leaves the exchange with the reason, so the client stops at once.
/// Destroying the responder (the nodelet unloaded) leaves the exchange too.
template <class Req, class Resp>
class ExchangeResponder {
 public:
  using RespPtr = boost::shared_ptr<const Resp>;
  using Answer = std::function<RespPtr(const Req&)>;
  using Report = std::function<void(const std::string&)>;

  /// `who` names the side in messages ("terrain"); `error` and `info` report (the nodelet's log).
  ExchangeResponder(std::unique_ptr<ExchangeServer<Req, Resp>> server, std::string who, Answer answer, Report error,
                    Report info)
      : server_(std::move(server)),
        who_(std::move(who)),
        answer_(std::move(answer)),
        error_(std::move(error)),
        info_(std::move(info)) {
    if (!server_->ServeInline([this](const boost::shared_ptr<const Req>& req) { return AnswerInline(*req); }))
      thread_ = std::thread([this] { Serve(); });
  }
  ~ExchangeResponder() {
    stop_ = true;
    server_->Leave("the " + who_ + " nodelet was unloaded");
    if (thread_.joinable()) thread_.join();
  }

 private:
  RespPtr Checked(const Req& req) {
    const long step = static_cast<long>(req.step);
    if (step <= last_step_)
      throw ExchangeError("request of step " + std::to_string(step) + " after step " + std::to_string(last_step_) +
                          ": the lock-step order is broken");
    RespPtr resp = answer_(req);
    last_step_ = step;
    return resp;
  }
  RespPtr AnswerInline(const Req& req) {
    try {
      return Checked(req);
    } catch (const std::exception& e) {
      error_(who_ + ": " + e.what());
      server_->LeaveFromHandler("the " + who_ + " failed: " + e.what());
      return nullptr;
    }
  }
  void Serve() {
    std::string why;
    try {
      while (auto req = server_->Wait(stop_, &why)) server_->Reply(Checked(*req));
      info_(who_ + ": the exchange ended (" + why + ")");
    } catch (const std::exception& e) {
      error_(who_ + ": " + e.what());
      server_->Leave("the " + who_ + " failed: " + e.what());
    }
  }

  std::unique_ptr<ExchangeServer<Req, Resp>> server_;
  std::string who_;
  Answer answer_;
  Report error_, info_;
  long last_step_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// A nodelet that answers an exchange but could not start: in one manager it leaves the channel
/// closed with the reason (the client then stops the run and writes its result); a standalone one
/// ends its process. Returns the channel to hold while the nodelet lives.
template <class Req, class Resp>
std::shared_ptr<Channel<Req, Resp>> RefuseExchange(const std::string& transport, const std::string& name,
                                                   const std::string& why) {
  if (transport == "topics") {
    ros::requestShutdown();
    return nullptr;
  }
  auto ch = ChannelRegistry::Get<Req, Resp>(name);
  ch->Close(why);
  return ch;
}

}  // namespace dem_mobility
