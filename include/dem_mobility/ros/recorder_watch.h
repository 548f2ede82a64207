// The bag recorder's failure as a run sees it: the latched topic recorder/error (std_msgs/String,
// published by BagRecorderNodelet when the bag cannot be written: a full disk, a file size limit).
// The vehicle and the soil rigs watch it and end their run with its text as the error.
#pragma once

#include <atomic>
#include <mutex>
#include <string>

#include <ros/ros.h>
#include <std_msgs/String.h>

namespace dem_mobility {

class RecorderWatch {
 public:
  /// Subscribes to `recorder/error` in the namespace of `nh`.
  void Start(ros::NodeHandle& nh) {
    sub_ = nh.subscribe<std_msgs::String>("recorder/error", 1, [this](const std_msgs::String::ConstPtr& m) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = m->data;
      }
      failed_ = true;
    });
  }
  /// True once the recorder said it cannot write (cheap: polled every step).
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  /// What it said.
  std::string error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
  }

 private:
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::string error_;  ///< under mutex_
  std::atomic<bool> failed_{false};
};

}  // namespace dem_mobility
