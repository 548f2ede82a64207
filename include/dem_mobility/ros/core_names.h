// The ROS layer names the core's types (namespace dem_mobility::core) without the prefix. Where a
// core type and a message share a name (DriverInput, DriverCommand: the same thing on either side
// of the exchange), the message is written dem_mobility::X and the core type core::X.
#pragma once

namespace dem_mobility {
namespace core {}
using namespace core;
}  // namespace dem_mobility
