// Core types <-> messages of the lock-step exchange (exact: every number is a float64 both ways),
// and the parameter plumbing every nodelet shares.
#pragma once

#include <string>
#include <vector>

#include <ros/ros.h>

#include "dem_mobility/DriverCommand.h"
#include "dem_mobility/DriverInput.h"
#include "dem_mobility/WheelStates.h"
#include "dem_mobility/WheelWrenches.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/vehicle/driver.h"
#include "dem_mobility/core/mobility/mobility_result.h"
#include "dem_mobility/ros/lockstep.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {

void ToMsg(const std::vector<WheelState>& s, WheelStates* m);
void FromMsg(const WheelStates& m, std::vector<WheelState>* s);
void ToMsg(const std::vector<WheelWrench>& w, WheelWrenches* m);
void FromMsg(const WheelWrenches& m, std::vector<WheelWrench>* w);
void ToMsg(const core::DriverInput& in, dem_mobility::DriverInput* m);
core::DriverInput FromMsg(const dem_mobility::DriverInput& m);
void ToMsg(const core::DriverCommand& c, dem_mobility::DriverCommand* m);
core::DriverCommand FromMsg(const dem_mobility::DriverCommand& m);

/// The scene every nodelet of a run reads, from the run's namespace `nh`: parameter `scene` (the
/// file) and the overrides under `override/` (e.g. override/grade_deg: 12, override/driver/kp: 4000;
/// empty strings are unset), applied as dotted key=value overrides. Throws ConfigError naming the
/// file (or the parameter).
MobilityRunParams LoadScene(const ros::NodeHandle& nh);
/// The same scene file with its overrides applied, for any kind of scene; `overrides` (if given)
/// receives them as key=value (what a checkpoint records of the run).
YamlReader LoadSceneFile(const ros::NodeHandle& nh, std::vector<std::string>* overrides = nullptr);
/// The exchange settings of a nodelet: `exchange_transport`, `exchange_spin` [s],
/// `peer_timeout` [s], `startup_timeout` [s].
ExchangeTiming LoadExchangeTiming(const ros::NodeHandle& pnh, std::string* transport);

inline const char* ParamTypeName(const std::string&) { return "a string"; }
inline const char* ParamTypeName(const double&) { return "a number"; }
inline const char* ParamTypeName(const int&) { return "an integer"; }
inline const char* ParamTypeName(const bool&) { return "true or false"; }
inline const char* ParamTypeName(const std::vector<std::string>&) { return "a list of strings"; }
/// A number given as a string (roslaunch makes `1e-4`, without a '.', a string): parsed whole.
bool NumberFromString(const ros::NodeHandle& nh, const std::string& name, double* value);
template <class T>
bool NumberFromString(const ros::NodeHandle&, const std::string&, T*) {
  return false;
}
/// The parameter `name` of `nh` into *value, which keeps its default when the parameter is not
/// set; ConfigError naming the parameter when it is set but not of the type asked for (ros's
/// NodeHandle::param would take the default without a word: `wait_for_recorder:=yes`).
template <class T>
void Param(const ros::NodeHandle& nh, const std::string& name, T* value) {
  if (!nh.hasParam(name)) return;
  if (!nh.getParam(name, *value) && !NumberFromString(nh, name, value))
    throw ConfigError("parameter " + nh.resolveName(name) + " is not " + ParamTypeName(*value));
}
/// A rate parameter [Hz of simulated time] as Param, then checked: finite, at least 1e-6 Hz (a
/// period a step count can hold) and at most 1e9 Hz, or 0 where `zero` says what 0 means.
void RateParam(const ros::NodeHandle& nh, const std::string& name, double* value, const char* zero = nullptr);

}  // namespace dem_mobility
