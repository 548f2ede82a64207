// The terrain's figures for a run's result within the process the nodelets share (the nodelet
// manager), for when the service terrain/report cannot give them: on Ctrl-C the manager's ROS shuts
// down (no service call goes through any more) and roslaunch unloads the nodelets, each at its own
// moment, while the vehicle writes its interrupted result. The terrain nodelet opens its entry here
// under its service's name as it loads: while it is loaded, reading the entry asks the terrain
// itself (the service's own answer); as it unloads, once its side of the exchange is closed, it
// leaves its last answer there. The vehicle asks the service first (the terrain may run in another
// process, standalone) and this board when the service cannot answer.
#pragma once

#include <functional>
#include <string>

#include "dem_mobility/TerrainReport.h"

namespace dem_mobility {

class TerrainFiguresBoard {
 public:
  using Answer = std::function<TerrainReport::Response()>;
  /// The terrain under service name `name` answers through `answer` until Close(name).
  static void Open(const std::string& name, Answer answer);
  /// Asks the terrain for its last answer and keeps that in place of the terrain (which may then go).
  static void Close(const std::string& name);
  /// The terrain's answer (asked now while it is loaded, its last one once it has closed); false when
  /// no terrain of that name is or was in this process.
  static bool Read(const std::string& name, TerrainReport::Response* out);
};

}  // namespace dem_mobility
