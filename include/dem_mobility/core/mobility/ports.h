// The co-simulation's peers as the vehicle sees them: a terrain (wheel states in, wheel wrenches
// out, every coupling interval) and a driver (speeds in, a command out, every control period).
// The in-process runner reaches them by direct calls (the ports here); the vehicle nodelet reaches
// them through lock-step exchanges with the terrain and driver nodelets (same interface).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dem_mobility/core/common/exchange.h"
#include "dem_mobility/core/vehicle/driver.h"

namespace dem_mobility::core {

class TerrainModel;
struct VehicleSpec;

/// The terrain: wheel states of step `step` at time `t` in, the wrenches for that step out; the
/// terrain then advances to t + dt (`dt`: the time to the next exchange, 0 at the opening exchange
/// before the step is chosen).
class TerrainPort {
 public:
  virtual ~TerrainPort() = default;
  virtual void Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                        std::vector<WheelWrench>* wrenches) = 0;
  /// The terrain behind the port (what results report).
  virtual const TerrainDescription& description() const = 0;
};

/// The driver.
class DriverPort {
 public:
  virtual ~DriverPort() = default;
  virtual DriverCommand Exchange(const DriverInput& in) = 0;
};

/// A terrain model called directly (same process, same thread): synchronize, wrenches, advance.
class LocalTerrainPort final : public TerrainPort {
 public:
  explicit LocalTerrainPort(TerrainModel& model) : model_(model) {}
  void Exchange(long step, double t, double dt, const std::vector<WheelState>& states,
                std::vector<WheelWrench>* wrenches) override;
  const TerrainDescription& description() const override;

 private:
  TerrainModel& model_;
};

/// The scene's speed driver for a vehicle (its mass, wheel radius, driveline reduction and engine
/// curves, from the vehicle's spec: the driver never builds the vehicle).
class SceneDriver final : public DriverPort {
 public:
  SceneDriver(const DriverParams& p, const VehicleSpec& vehicle);
  DriverCommand Exchange(const DriverInput& in) override;
  template <class Ar>
  void Io(Ar& ar) {
    ar.Tag("driver");
    driver_.Io(ar);
  }

 private:
  PowertrainParams powertrain_;  ///< the driver's engine curves (SpeedDriver refers to them)
  SpeedDriver driver_;
};

}  // namespace dem_mobility::core
