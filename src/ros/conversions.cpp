#include "dem_mobility/ros/conversions.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/ros/core_names.h"

namespace dem_mobility {
namespace {
geometry_msgs::Vector3 V(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}
Eigen::Vector3d E(const geometry_msgs::Vector3& m) { return {m.x, m.y, m.z}; }
}  // namespace

void ToMsg(const std::vector<WheelState>& s, WheelStates* m) {
  m->poses.resize(s.size());
  m->twists.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    auto& p = m->poses[i];
    p.position.x = s[i].position.x();
    p.position.y = s[i].position.y();
    p.position.z = s[i].position.z();
    p.orientation.w = s[i].orientation.w();
    p.orientation.x = s[i].orientation.x();
    p.orientation.y = s[i].orientation.y();
    p.orientation.z = s[i].orientation.z();
    m->twists[i].linear = V(s[i].velocity);
    m->twists[i].angular = V(s[i].angular_velocity);
  }
}

void FromMsg(const WheelStates& m, std::vector<WheelState>* s) {
  DM_THROW_UNLESS(m.poses.size() == m.twists.size(), "WheelStates step ", m.step, ": ", m.poses.size(), " poses but ",
                  m.twists.size(), " twists");
  s->resize(m.poses.size());
  for (size_t i = 0; i < m.poses.size(); ++i) {
    const auto& p = m.poses[i];
    (*s)[i].position = {p.position.x, p.position.y, p.position.z};
    (*s)[i].orientation = Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
    (*s)[i].velocity = E(m.twists[i].linear);
    (*s)[i].angular_velocity = E(m.twists[i].angular);
  }
}

void ToMsg(const std::vector<WheelWrench>& w, WheelWrenches* m) {
  const size_t n = w.size();
  m->wrenches.resize(n);
  m->sinkage.resize(n);
  m->contacts.resize(n);
  m->normal_force.resize(n);
  m->stiffness.resize(n);
  m->damping.resize(n);
  for (size_t i = 0; i < n; ++i) {
    m->wrenches[i].force = V(w[i].force);
    m->wrenches[i].torque = V(w[i].moment);
    m->sinkage[i] = w[i].sinkage;
    m->contacts[i] = static_cast<uint32_t>(w[i].contacts);
    m->normal_force[i] = w[i].normal_force;
    m->stiffness[i] = w[i].stiffness;
    m->damping[i] = w[i].damping;
  }
}

void FromMsg(const WheelWrenches& m, std::vector<WheelWrench>* w) {
  const size_t n = m.wrenches.size();
  DM_THROW_UNLESS(m.sinkage.size() == n && m.contacts.size() == n && m.normal_force.size() == n &&
                      m.stiffness.size() == n && m.damping.size() == n,
                  "WheelWrenches step ", m.step, ": arrays of different lengths");
  w->resize(n);
  for (size_t i = 0; i < n; ++i) {
    (*w)[i].force = E(m.wrenches[i].force);
    (*w)[i].moment = E(m.wrenches[i].torque);
    (*w)[i].sinkage = m.sinkage[i];
    (*w)[i].contacts = static_cast<int>(m.contacts[i]);
    (*w)[i].normal_force = m.normal_force[i];
    (*w)[i].stiffness = m.stiffness[i];
    (*w)[i].damping = m.damping[i];
  }
}

void ToMsg(const core::DriverInput& in, dem_mobility::DriverInput* m) {
  m->step = static_cast<uint64_t>(in.step);
  m->time = in.time;
  m->period = in.period;
  m->forward_speed = in.forward_speed;
  m->drive_shaft_speed = in.drive_shaft_speed;
  m->lateral_offset = in.lateral_offset;
  m->heading = in.heading;
}

core::DriverInput FromMsg(const dem_mobility::DriverInput& m) {
  core::DriverInput in;
  in.step = static_cast<long>(m.step);
  in.time = m.time;
  in.period = m.period;
  in.forward_speed = m.forward_speed;
  in.drive_shaft_speed = m.drive_shaft_speed;
  in.lateral_offset = m.lateral_offset;
  in.heading = m.heading;
  return in;
}

void ToMsg(const core::DriverCommand& c, dem_mobility::DriverCommand* m) {
  m->speed_command = c.speed_command;
  m->torque_request = c.torque_request;
  m->drive_torque = c.drive_torque;
  m->brake_effort = c.brake_effort;
  m->steering = c.steering;
  m->wot_limited = c.wot_limited;
}

core::DriverCommand FromMsg(const dem_mobility::DriverCommand& m) {
  core::DriverCommand c;
  c.speed_command = m.speed_command;
  c.torque_request = m.torque_request;
  c.drive_torque = m.drive_torque;
  c.brake_effort = m.brake_effort;
  c.steering = m.steering;
  c.wot_limited = m.wot_limited;
  return c;
}

namespace {
void Flatten(const XmlRpc::XmlRpcValue& v, const std::string& prefix, std::vector<std::string>* out) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeStruct:
      for (auto it = v.begin(); it != v.end(); ++it)
        Flatten(it->second, prefix.empty() ? it->first : prefix + "." + it->first, out);
      break;
    case XmlRpc::XmlRpcValue::TypeString: {
      const std::string s = static_cast<std::string>(const_cast<XmlRpc::XmlRpcValue&>(v));
      if (!s.empty()) out->push_back(prefix + "=" + s);
      break;
    }
    case XmlRpc::XmlRpcValue::TypeDouble: {
      // every digit (17 significant): the override is the number given, not a rounded one
      std::ostringstream text;
      text.precision(17);
      text << static_cast<double>(const_cast<XmlRpc::XmlRpcValue&>(v));
      out->push_back(prefix + "=" + text.str());
      break;
    }
    case XmlRpc::XmlRpcValue::TypeInt:
      out->push_back(prefix + "=" + std::to_string(static_cast<int>(const_cast<XmlRpc::XmlRpcValue&>(v))));
      break;
    case XmlRpc::XmlRpcValue::TypeBoolean:
      out->push_back(prefix + "=" + (static_cast<bool>(const_cast<XmlRpc::XmlRpcValue&>(v)) ? "true" : "false"));
      break;
    default:
      throw ConfigError("parameter override/" + prefix + ": only numbers, strings and booleans can override a scene key");
  }
}
}  // namespace

MobilityRunParams LoadScene(const ros::NodeHandle& nh) { return MobilityRunParams::Read(LoadSceneFile(nh)); }

YamlReader LoadSceneFile(const ros::NodeHandle& nh, std::vector<std::string>* given) {
  std::string file;
  if (!nh.getParam("scene", file) || file.empty())
    throw ConfigError("parameter " + nh.resolveName("scene") + " (the scene file) is not set");
  std::vector<std::string> overrides;
  XmlRpc::XmlRpcValue o;
  if (nh.getParam("override", o)) Flatten(o, "", &overrides);
  if (given) *given = overrides;
  // relative paths in overrides (vehicle:=, terrain:=) are the user's, relative to where they ran
  return YamlReader::LoadWithOverrides(file, overrides);
}

bool NumberFromString(const ros::NodeHandle& nh, const std::string& name, double* value) {
  std::string text;
  if (!nh.getParam(name, text) || text.empty()) return false;
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return false;
  *value = x;
  return true;
}

void RateParam(const ros::NodeHandle& nh, const std::string& name, double* value, const char* zero) {
  Param(nh, name, value);
  const double r = *value;
  if (zero && r == 0.0) return;
  if (!(std::isfinite(r) && r >= 1e-6 && r <= 1e9))
    throw ConfigError("parameter " + nh.resolveName(name) + ": " + std::to_string(r) + " Hz: a rate is from 1e-6 to 1e9 Hz" +
                      (zero ? std::string(" (0: ") + zero + ")" : std::string()));
}

ExchangeTiming LoadExchangeTiming(const ros::NodeHandle& pnh, std::string* transport) {
  ExchangeTiming t;
  *transport = "inline";
  Param(pnh, "exchange_transport", transport);
  Param(pnh, "exchange_spin", &t.spin);
  Param(pnh, "peer_timeout", &t.peer_timeout);
  Param(pnh, "startup_timeout", &t.startup_timeout);
  if (*transport != "inline" && *transport != "shared_memory" && *transport != "topics")
    throw ConfigError("parameter " + pnh.resolveName("exchange_transport") + ": '" + *transport +
                      "' is not a transport (inline, shared_memory or topics)");
  if (!(t.spin >= 0.0 && t.spin <= 1.0)) throw ConfigError("parameter " + pnh.resolveName("exchange_spin") + " must be in [0, 1] s");
  // (at most about 30 years: the timeouts become whole nanoseconds in an int64)
  if (!(t.peer_timeout > 0.0 && t.peer_timeout <= 1e9))
    throw ConfigError("parameter " + pnh.resolveName("peer_timeout") + " must be in (0, 1e9] s");
  if (!(t.startup_timeout > 0.0 && t.startup_timeout <= 1e9))
    throw ConfigError("parameter " + pnh.resolveName("startup_timeout") + " must be in (0, 1e9] s");
  return t;
}

}  // namespace dem_mobility
