// dem_mobility/BagRecorderNodelet: writes a run's topics to one bag from inside the nodelet
// manager. In the same process nothing is dropped (unbounded subscriber queues, no network), and
// the bag is written in simulation-time order (each message's header stamp is its record time;
// ties go by the order of ~topics), so the same run gives the same bag; a latched topic's message
// delivered twice (a race in roscpp) is recorded once. When the end topic (the
// mobility result) arrives, everything is flushed, the bag is closed and, if asked, the run ends.
// A bag that cannot be written (a full disk, a file size limit) is an error said at once: on the
// latched topic recorder/error (std_msgs/String; the vehicle and the rigs stop their run with it)
// and in the log; the process ignores SIGXFSZ, so a size limit fails the write instead of killing
// the manager with every nodelet in it.
#include <algorithm>
#include <csignal>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <sstream>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <rosbag/bag.h>
#include <std_msgs/String.h>
#include <topic_tools/shape_shifter.h>

#include "dem_mobility/ros/conversions.h"

namespace dem_mobility {
namespace {

/// Byte offset of the header stamp in a serialized message of this definition: 4 for a message
/// whose first field is a Header (after seq), 8 for an array of such messages (after the length and
/// the first element's seq), -1 when there is none.
int StampOffset(const std::string& definition) {
  auto first_field = [](const std::string& text, size_t from, size_t to) -> std::string {
    std::istringstream in(text.substr(from, to - from));
    std::string line;
    while (std::getline(in, line)) {
      const size_t a = line.find_first_not_of(" \t");
      if (a == std::string::npos || line[a] == '#') continue;
      if (line.compare(a, 4, "MSG:") == 0 || line.compare(a, 3, "===") == 0) continue;
      if (line.find('=') != std::string::npos) continue;  // a constant
      return line.substr(a, line.find_first_of(" \t", a) - a);
    }
    return "";
  };
  const size_t sep = definition.find("\n=====");
  const std::string type = first_field(definition, 0, sep == std::string::npos ? definition.size() : sep);
  auto is_header = [](const std::string& t) { return t == "Header" || t == "std_msgs/Header"; };
  if (is_header(type)) return 4;
  if (type.size() > 2 && type.compare(type.size() - 2, 2, "[]") == 0) {
    const std::string elem = type.substr(0, type.size() - 2);
    const std::string bare = elem.substr(elem.rfind('/') == std::string::npos ? 0 : elem.rfind('/') + 1);
    size_t pos = 0;
    while ((pos = definition.find("MSG: ", pos)) != std::string::npos) {
      const size_t eol = definition.find('\n', pos);
      const std::string name = definition.substr(pos + 5, eol - pos - 5);
      const size_t slash = name.rfind('/');
      if (name == elem || name.substr(slash == std::string::npos ? 0 : slash + 1) == bare) {
        const size_t next = definition.find("\n=====", eol);
        return is_header(first_field(definition, eol, next == std::string::npos ? definition.size() : next)) ? 8 : -1;
      }
      pos = eol;
    }
  }
  return -1;
}

}  // namespace

class BagRecorderNodelet : public nodelet::Nodelet {
 public:
  ~BagRecorderNodelet() override {
    std::lock_guard<std::mutex> lock(mutex_);
    Close("the recorder was unloaded before the end of the run");
  }

 private:
  struct Pending {
    ros::Time stamp;
    topic_tools::ShapeShifter::ConstPtr msg;
    boost::shared_ptr<ros::M_string> header;
  };
  struct Topic {
    std::string name;     ///< resolved
    bool stream = false;  ///< gates the ordering (publishes all run long)
    bool latched = false; ///< replayed latched (rosbag play honours the flag), so a late rviz sees it
    int stamp_offset = -2;///< -2: not yet known
    ros::Time latest;     ///< newest stamp received
    bool seen = false;
    long count = 0;
    bool seen_latched = false;          ///< a message from a latching publisher was received
    std::vector<uint8_t> last_latched;  ///< the last one, serialized
    std::deque<Pending> queue;
    ros::Subscriber sub;
  };

  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    std::vector<std::string> topics, stream, latched;
    std::string end;
    // every parameter checked before the bag is made: a parameter of the wrong type is an error
    // naming it, never its default (Param)
    if (!pnh.getParam("bag", path_) || path_.empty()) return Fatal("parameter " + pnh.resolveName("bag") + " is not set");
    if (!pnh.getParam("topics", topics) || topics.empty())
      return Fatal("parameter " + pnh.resolveName("topics") + " (the list of topics to record) is not set");
    // without a stream topic nothing could be written before the end: the whole run held in memory
    if (!pnh.getParam("stream_topics", stream) || stream.empty())
      return Fatal("parameter " + pnh.resolveName("stream_topics") +
                   " (the topics published all run long, which order the bag) is not a list of topics");
    try {
      Param(pnh, "latched_topics", &latched);
      Param(pnh, "end_topic", &end);
      Param(pnh, "shutdown_when_done", &shutdown_when_done_);
    } catch (const std::exception& e) {
      return Fatal(e.what());
    }
    for (const auto& [name, list] : {std::pair<const char*, const std::vector<std::string>*>{"stream_topics", &stream},
                                     {"latched_topics", &latched}})
      for (const std::string& s : *list)
        if (std::find(topics.begin(), topics.end(), s) == topics.end())
          return Fatal("parameter " + pnh.resolveName(name) + ": '" + s + "' is not in ~topics");
    if (!end.empty() && std::find(topics.begin(), topics.end(), end) == topics.end())
      return Fatal("parameter " + pnh.resolveName("end_topic") + ": '" + end + "' is not in ~topics");
    // a file size limit (ulimit -f) fails the bag's writes (EFBIG) instead of killing the process
    std::signal(SIGXFSZ, SIG_IGN);
    error_ = nh.advertise<std_msgs::String>("recorder/error", 1, true);
    try {
      const std::filesystem::path parent = std::filesystem::path(path_).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      bag_->open(path_, rosbag::bagmode::Write);
    } catch (const std::exception& e) {
      return Fatal("parameter " + pnh.resolveName("bag") + ": cannot write the bag '" + path_ + "': " + e.what());
    }
    open_ = true;
    topics_.resize(topics.size());
    for (size_t i = 0; i < topics.size(); ++i) {
      Topic& t = topics_[i];
      t.name = nh.resolveName(topics[i]);
      t.stream = std::find(stream.begin(), stream.end(), topics[i]) != stream.end();
      t.latched = std::find(latched.begin(), latched.end(), topics[i]) != latched.end();
      if (topics[i] == end) end_index_ = static_cast<int>(i);
    }
    // unbounded queues (0): in this process nothing is dropped
    // the callback takes the message event, so that it has the connection header (who published,
    // whether the publisher latches): bound to a plain message pointer it would not
    using Event = const ros::MessageEvent<topic_tools::ShapeShifter const>&;
    for (size_t i = 0; i < topics_.size(); ++i) {
      topics_[i].sub = nh.subscribe<topic_tools::ShapeShifter, Event>(
          topics_[i].name, 0, boost::bind(&BagRecorderNodelet::OnMessage, this, i, boost::placeholders::_1));
    }
    NODELET_INFO("recording %zu topics to %s", topics_.size(), path_.c_str());
  }

  void Fatal(const std::string& what) {
    NODELET_FATAL("%s", what.c_str());
    ros::requestShutdown();
  }

  void OnMessage(size_t index, const ros::MessageEvent<topic_tools::ShapeShifter const>& event) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!open_) {
      // a bag that failed still ends the run when asked, once the result (which carries the error) is out
      if (failed_ && static_cast<int>(index) == end_index_ && shutdown_when_done_) ros::requestShutdown();
      return;
    }
    Topic& t = topics_[index];
    const auto& msg = event.getConstMessage();
    if (t.stamp_offset == -2) t.stamp_offset = StampOffset(msg->getMessageDefinition());
    ros::Time stamp = last_written_;
    // whether the publisher latches, from the connection header roscpp builds for it
    bool latched_publisher = false;
    if (const auto connection = event.getConnectionHeaderPtr()) {
      const auto latching = connection->find("latching");
      latched_publisher = latching != connection->end() && latching->second == "1";
    }
    std::vector<uint8_t> buf;
    if (latched_publisher || t.stamp_offset >= 0) {
      buf.resize(msg->size());
      ros::serialization::OStream out(buf.data(), buf.size());
      msg->write(out);
    }
    if (latched_publisher) {
      // roscpp can hand a latched message to a subscriber twice when the subscriber connects while
      // it is being published (Publication::addSubscriberLink sends the latched copy after it has
      // let go of the lock the publish takes): the same bytes again are that copy, not a new state
      if (t.seen_latched && buf == t.last_latched) return;
      t.seen_latched = true;
      t.last_latched = buf;
    }
    if (t.stamp_offset >= 0 && msg->size() >= static_cast<uint32_t>(t.stamp_offset) + 8) {
      const bool array = t.stamp_offset == 8;
      uint32_t n = 1, sec, nsec;
      if (array) std::memcpy(&n, buf.data(), 4);
      if (n > 0) {
        std::memcpy(&sec, buf.data() + t.stamp_offset, 4);
        std::memcpy(&nsec, buf.data() + t.stamp_offset + 4, 4);
        stamp = ros::Time(sec, nsec);
      }
    }
    // the connection header the bag keeps: what the message is, who sent it, whether it was
    // latched (so that a replay latches it again); nothing that changes from run to run
    auto header = boost::make_shared<ros::M_string>();
    (*header)["topic"] = t.name;
    (*header)["type"] = msg->getDataType();
    (*header)["md5sum"] = msg->getMD5Sum();
    (*header)["message_definition"] = msg->getMessageDefinition();
    (*header)["callerid"] = event.getPublisherName();
    (*header)["latching"] = t.latched ? "1" : "0";
    t.queue.push_back({stamp, msg, header});
    ++t.count;
    if (t.stream) {
      t.latest = stamp;
      t.seen = true;
    }
    if (static_cast<int>(index) == end_index_) {
      Close("");
      if (shutdown_when_done_) ros::requestShutdown();
      return;
    }
    // a message older than the newest of every stream topic can no longer be preceded by another
    // (there is one at least: ~stream_topics must name one)
    ros::Time safe = ros::TIME_MAX;
    for (const Topic& s : topics_) {
      if (!s.stream) continue;
      if (!s.seen) return;
      safe = std::min(safe, s.latest);
    }
    WriteOrFail(safe);
  }

  /// Write, and on failure (the disk full, the file size limit, an I/O error) the error said on
  /// recorder/error and in the log; nothing more is recorded.
  void WriteOrFail(const ros::Time& limit) {
    try {
      Write(limit);
    } catch (const std::exception& e) {
      Failed(e.what());
    }
  }

  /// The bag cannot be written: said, and the bag let go. (rosbag::Bag closes itself in its
  /// destructor, which throws when the index cannot be written either: the object is left
  /// behind, its file descriptor to the process's end.)
  void Failed(const std::string& what) {
    open_ = false;
    failed_ = true;
    std_msgs::String m;
    m.data = "the bag recorder cannot write " + path_ + " (disk full or a file size limit?): " + what;
    NODELET_FATAL("%s", m.data.c_str());
    error_.publish(m);
    (void)bag_.release();
  }

  /// Writes every queued message stamped before `limit`, oldest first (ties in topic order).
  void Write(const ros::Time& limit) {
    for (;;) {
      int best = -1;
      for (size_t i = 0; i < topics_.size(); ++i) {
        const auto& q = topics_[i].queue;
        if (q.empty() || !(q.front().stamp < limit)) continue;
        if (best < 0 || q.front().stamp < topics_[best].queue.front().stamp) best = static_cast<int>(i);
      }
      if (best < 0) return;
      Pending p = std::move(topics_[best].queue.front());
      topics_[best].queue.pop_front();
      // rosbag refuses record times below TIME_MIN (the stamp 0 of the first messages)
      const ros::Time record = std::max(p.stamp, ros::TIME_MIN);
      bag_->write(topics_[best].name, record, *p.msg, p.header);
      last_written_ = std::max(last_written_, p.stamp);
    }
  }

  void Close(const std::string& why) {
    if (!open_) return;
    open_ = false;
    try {
      Write(ros::TIME_MAX);
      bag_->close();
    } catch (const std::exception& e) {
      Failed(e.what());
      return;
    }
    std::ostringstream counts;
    for (const Topic& t : topics_) counts << " " << t.name << "=" << t.count;
    if (why.empty()) NODELET_INFO("bag %s closed:%s", path_.c_str(), counts.str().c_str());
    else NODELET_WARN("bag %s closed early (%s):%s", path_.c_str(), why.c_str(), counts.str().c_str());
  }

  std::mutex mutex_;
  std::string path_;
  std::unique_ptr<rosbag::Bag> bag_ = std::make_unique<rosbag::Bag>();
  ros::Publisher error_;
  bool open_ = false, failed_ = false, shutdown_when_done_ = false;
  std::vector<Topic> topics_;
  int end_index_ = -1;
  ros::Time last_written_;
};

}  // namespace dem_mobility

PLUGINLIB_EXPORT_CLASS(dem_mobility::BagRecorderNodelet, nodelet::Nodelet)
