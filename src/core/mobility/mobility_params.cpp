#include "dem_mobility/core/mobility/mobility_params.h"

#include <cmath>
#include <functional>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"

namespace dem_mobility::core {

MobilityRunParams MobilityRunParams::Read(const YamlReader& y) {
  MobilityRunParams p;
  p.file = y.file();
  const std::string scene = y.String("scene");
  if (scene != "road_slope" && scene != "soil_slope")
    y.Fail("scene", "expected 'road_slope' or 'soil_slope', found '" + scene + "'");
  p.kind = scene;
  p.vehicle_file = y.ResolvePath(y.String("vehicle"));
  p.terrain_file = y.ResolvePath(y.String("terrain"));
  if (y.Has("terrain_overrides")) {
    // (nested maps, as `terrain_overrides.levels.tiny.length=6` on the command line makes them,
    // stand for dotted keys of the terrain file)
    const std::function<void(const YamlReader&, const std::string&)> flatten = [&](const YamlReader& o,
                                                                                   const std::string& prefix) {
      for (const std::string& k : o.Keys()) {
        if (o.IsMap(k))
          flatten(o.Child(k), prefix + k + ".");
        else if (o.IsList(k))  // (terrain_overrides.patch.check_window=[0.3,0.7])
          p.terrain_overrides.push_back(prefix + k + "=" + o.FlowText(k));
        else if (!o.Has(k))  // null (terrain_overrides.cone_index=~: the file's cone index unset, f given instead)
          p.terrain_overrides.push_back(prefix + k + "=~");
        else
          p.terrain_overrides.push_back(prefix + k + "=" + o.String(k));
      }
      o.Finish();
    };
    flatten(y.Child("terrain_overrides"), "");
  }
  p.grade_deg = y.DoubleIn("grade_deg", -45.0, 45.0);
  p.side_slope_deg = y.DoubleIn("side_slope_deg", -45.0, 45.0, 0.0);
  p.start_height = y.DoubleIn("start_height", 0.0, 5.0, 0.0);
  p.start_speed = y.DoubleIn("start_speed", 0.0, 40.0, 0.0);
  p.duration = y.DoubleIn("duration", 1e-3, 3600.0);
  p.settle_time = y.DoubleIn("settle_time", 0.0, 10.0, 0.5);
  if (y.Has("time_step") && y.String("time_step") != "auto") p.time_step = y.DoubleIn("time_step", 1e-7, 1e-2);
  p.time_step_safety = y.DoubleIn("time_step_safety", 0.01, 1.0, 0.9);
  p.time_step_guard = y.Bool("time_step_guard", true);
  p.coupling_interval = y.Int("coupling_interval", 1);
  if (p.coupling_interval < 1 || p.coupling_interval > 1000)
    y.Fail("coupling_interval", "must be a whole number of steps in [1, 1000], found " + std::to_string(p.coupling_interval));
  p.driver = DriverParams::Read(y.Child("driver"));
  const YamlReader res = y.Child("result");
  p.sample_rate = res.DoubleIn("sample_rate", 1.0, 1e5, 100.0);
  p.plateau.window = res.DoubleIn("plateau_window", 0.5, 60.0, 5.0);
  p.plateau.tolerance = res.Positive("plateau_tolerance", 0.05);
  p.plateau.scatter = res.Positive("plateau_scatter", 0.1);
  p.plateau.end_tolerance = res.Positive("plateau_end_tolerance", 0.1);
  p.plateau.full_throttle = res.DoubleIn("plateau_full_throttle", 0.01, 1.0, 0.5);
  p.plateau.stall_speed = res.Positive("stall_speed", 0.2);
  p.plateau.stall_time = res.Positive("stall_time", 5.0);
  p.end_when_steady = res.Bool("end_when_steady", false);
  res.Finish();
  y.Finish();
  return p;
}

Eigen::Vector3d MobilityRunParams::Gravity() const {
  const double a = grade_deg * M_PI / 180.0, b = side_slope_deg * M_PI / 180.0;
  return 9.81 * Eigen::Vector3d(-std::sin(a), -std::cos(a) * std::sin(b), -std::cos(a) * std::cos(b));
}

}  // namespace dem_mobility::core
