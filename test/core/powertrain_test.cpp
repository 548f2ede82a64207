// Drive-torque clamp between the engine-brake and WOT tables (paper fig. 16) and the brakes.
#include <gtest/gtest.h>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/vehicle/driver.h"
#include "dem_mobility/core/vehicle/powertrain.h"

namespace dem_mobility::core {
namespace {

PowertrainParams Hmmwv() {
  return PowertrainParams::Read(YamlReader::Load(DM_CONFIG_DIR "/vehicles/hmmwv/powertrain.yaml"));
}

TEST(Powertrain, ClampFollowsTheTablesAtSeveralSpeeds) {
  const PowertrainParams p = Hmmwv();
  // rows of powertrain.yaml (derived from vehicle-data.md section 5)
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(1e9, 20.0), 6424.0);
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(1e9, 125.0), 1885.0);
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(1e9, 350.0), 685.0);
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(1e9, 137.5), 0.5 * (1885.0 + 1278.0));  // interpolated
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(1e9, 5.0), 3033.0);  // held below the first speed
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(-1e9, 30.0), -176.0);
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(-1e9, 300.0), -22.0);
  EXPECT_DOUBLE_EQ(p.ClampDriveTorque(500.0, 125.0), 500.0);  // inside the envelope: unchanged
}

TEST(Powertrain, BrakeSticksBelowItsCapAndSlidesAtIt) {
  const PowertrainParams p = Hmmwv();
  double anchor = 0.0;
  // small deflection: spring torque, no sliding
  EXPECT_NEAR(p.BrakeTorque(1.0, 0.01, 0.0, &anchor), -p.brake_stiffness * 0.01, 1e-9);
  EXPECT_EQ(anchor, 0.0);
  // large deflection at half effort: capped at 0.5 x 4000 N m, anchor slides
  EXPECT_NEAR(p.BrakeTorque(0.5, 1.0, 0.0, &anchor), -2000.0, 1e-9);
  EXPECT_NEAR(anchor, 1.0 - 2000.0 / p.brake_stiffness, 1e-12);
  // released: no torque
  EXPECT_EQ(p.BrakeTorque(0.0, 2.0, 3.0, &anchor), 0.0);
}

TEST(Driver, RequestsWotWhenTheCommandOutrunsTheVehicle) {
  const PowertrainParams p = Hmmwv();
  DriverParams d;
  d.accel = 1.0;
  d.v_max = 25.0;
  d.kp = 5000;
  d.ki = 500;
  SpeedDriver drv(d, p, 4863.0, 0.485, 0.2);
  EXPECT_DOUBLE_EQ(drv.SpeedCommand(10.0), 10.0);
  EXPECT_DOUBLE_EQ(drv.SpeedCommand(40.0), 25.0);
  // far behind the command at 125 rad/s: the request exceeds WOT, clamp to the table
  const DriverCommand c = drv.Update(20.0, 1e-3, 5.0, 125.0);
  EXPECT_TRUE(c.wot_limited);
  EXPECT_DOUBLE_EQ(c.drive_torque, 1885.0);
  EXPECT_EQ(c.brake_effort, 0.0);
  // far ahead of the command: below the engine brake, the brakes take the rest
  SpeedDriver drv2(d, p, 4863.0, 0.485, 0.2);
  const DriverCommand b = drv2.Update(5.0, 1e-3, 15.0, 150.0);
  EXPECT_DOUBLE_EQ(b.drive_torque, -29.0);
  EXPECT_GT(b.brake_effort, 0.0);
}

TEST(Driver, CommandIsClampedToTheTablesAtSeveralDriveShaftSpeeds) {
  // the driver nodelet's SpeedDriver: far behind its command it gets the WOT row, far ahead the
  // engine-brake row of powertrain.yaml, at each drive-shaft speed
  const PowertrainParams p = Hmmwv();
  DriverParams d;
  d.kp = 5000;
  d.ki = 500;
  const struct {
    double w, wot;
  } wot_rows[] = {{20.0, 6424.0}, {125.0, 1885.0}, {350.0, 685.0}};
  for (const auto& r : wot_rows) {
    SpeedDriver drv(d, p, 4863.0, 0.485, 0.2);
    const DriverCommand c = drv.Update(20.0, 1e-3, 0.0, r.w);
    EXPECT_DOUBLE_EQ(c.drive_torque, r.wot) << "w = " << r.w;
    EXPECT_TRUE(c.wot_limited);
  }
  const struct {
    double w, eb;
  } brake_rows[] = {{30.0, -176.0}, {300.0, -22.0}};
  for (const auto& r : brake_rows) {
    SpeedDriver drv(d, p, 4863.0, 0.485, 0.2);
    const DriverCommand c = drv.Update(1.0, 1e-3, 20.0, r.w);
    EXPECT_DOUBLE_EQ(c.drive_torque, r.eb) << "w = " << r.w;
    EXPECT_FALSE(c.wot_limited);
    EXPECT_GT(c.brake_effort, 0.0);
  }
}

}  // namespace
}  // namespace dem_mobility::core
