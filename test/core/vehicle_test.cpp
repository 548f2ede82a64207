// The 33-body vehicle against statics and the power balance on a grade.
#include <gtest/gtest.h>

#include <cmath>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_scene.h"
#include "dem_mobility/core/vehicle/vehicle.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"

namespace dem_mobility::core {
namespace {

MobilityRunParams Scene(double grade) {
  MobilityRunParams p = MobilityRunParams::Read(YamlReader::Load(DM_CONFIG_DIR "/scenes/road_slope.yaml"));
  p.grade_deg = grade;
  return p;
}

constexpr const char* kHmmwv = DM_CONFIG_DIR "/vehicles/hmmwv/vehicle.yaml";

TEST(Vehicle, HasThePapersThirtyThreeBodies) {
  const std::unique_ptr<Vehicle> v = Vehicle::Build(VehicleSpec::Load(kHmmwv), Eigen::Vector3d::Zero());
  EXPECT_EQ(v->system().num_bodies() - 1, 33);  // minus the ground
  EXPECT_NEAR(v->system().TotalMass(), 4430.0 + 4 * (50.0 + 19.45 + 5.81 + 23.97) + 2 * 6.0 + 4 * 6.0, 1e-9);
}

// The driver and the terrain take mass, wheel radius and reduction from the spec alone: they must be
// those of the built vehicle, the mass to the last bit.
TEST(VehicleSpec, DerivedFiguresAreTheBuiltVehicles) {
  const VehicleSpec spec = VehicleSpec::Load(kHmmwv);
  const std::unique_ptr<Vehicle> v = Vehicle::Build(spec, Eigen::Vector3d(3.0, -1.5, 0.7));
  EXPECT_EQ(spec.TotalMass(), v->system().TotalMass());
  EXPECT_EQ(spec.wheel_radius(), v->tire().radius);
  EXPECT_EQ(spec.driveline_reduction(), v->driveline_reduction());
  EXPECT_EQ(spec.wheel_radius(), 0.485);
  EXPECT_EQ(spec.driveline_reduction(), 0.2);
}

// The total mass is the sprung mass (chassis with the parts it carries) plus the unsprung parts:
// per corner upright, arms and wheel, the front tie rods and the four half shafts, read here from
// the files directly.
TEST(VehicleSpec, TotalMassIsTheSumOfTheFileMasses) {
  const YamlReader top = YamlReader::Load(kHmmwv);
  double m = top.Child("chassis").Double("sprung_mass");
  for (const char* file : {"suspension_front", "suspension_rear"}) {
    const YamlReader masses = YamlReader::Load(top.ResolvePath(top.String(file))).Child("masses");
    for (const char* part : {"upright", "uca", "lca", "wheel"}) m += 2.0 * masses.Child(part).Double("mass");
    if (masses.Has("tierod")) m += 2.0 * masses.Child("tierod").Double("mass");
  }
  m += 4.0 * YamlReader::Load(top.ResolvePath(top.String("driveline"))).Child("half_shaft").Double("mass");
  EXPECT_NEAR(VehicleSpec::Load(kHmmwv).TotalMass(), m, 1e-12 * m);
}

TEST(Vehicle, AtRestWheelLoadsCarryTheWeightSplitByTheCom) {
  MobilityRun s(Scene(0.0));
  Vehicle& v = s.vehicle();
  MultibodySystem& sys = v.system();
  v.SetBrakeEffort(1.0);
  while (sys.time() < 2.0) s.sim().Step(s.terrain_port());
  const double W = sys.TotalMass() * 9.81;
  double total = 0;
  for (int i = 0; i < 4; ++i) total += v.WheelLoad(i);
  EXPECT_NEAR(total, W, 2e-3 * W);
  // moment balance about the rear axle: front load = W (x_com - x_rear) / (x_front - x_rear)
  const double xf = 0.5 * (sys.body(v.wheel(0)).x.x() + sys.body(v.wheel(1)).x.x());
  const double xr = 0.5 * (sys.body(v.wheel(2)).x.x() + sys.body(v.wheel(3)).x.x());
  const double front = W * (sys.CenterOfMass().x() - xr) / (xf - xr);
  EXPECT_NEAR(v.WheelLoad(0) + v.WheelLoad(1), front, 5e-3 * W);
  EXPECT_NEAR(v.WheelLoad(0), v.WheelLoad(1), 2e-3 * W);  // symmetric
  EXPECT_LT(sys.body(v.chassis()).v.norm(), 1e-3);
  // ride height: the springs hold the chassis within 2 cm of its design height
  EXPECT_NEAR(v.ChassisFramePosition().z(), v.design_ride_height(), 0.02);
}

// Steady speed where WOT(w) G / r = m g (sin th + c_rr cos th), w = v / (G r), on the falling part
// of the WOT table (bisection), independent of the simulation.
double PowerBalanceSpeed(const PowertrainParams& pt, double m, double r, double G, double th, double c_rr) {
  const double torque = m * 9.81 * r * G * (std::sin(th) + c_rr * std::cos(th));
  double lo = 125.0, hi = 386.0;  // WOT decreases monotonically over [125, 386] rad/s
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pt.wot(mid) > torque ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi) * G * r;
}

TEST(Vehicle, SteadySpeedOnAGradeMatchesThePowerBalance) {
  const double grade = 20.0;
  MobilityRunParams p = Scene(grade);
  p.duration = 25.0;
  MobilityRun s(p);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.smg.status, "steady");
  const Vehicle& v = s.vehicle();
  const double c_rr = YamlReader::Load(p.terrain_file).Child("contact").Double("c_rr");
  const double expected = PowerBalanceSpeed(v.powertrain(), v.system().TotalMass(), v.tire().radius,
                                            v.driveline_reduction(), grade * M_PI / 180.0, c_rr);
  EXPECT_NEAR(r.smg.value, expected, 0.05 * expected);
  // the plateau is the full-throttle one: the driver asks for more than WOT
  EXPECT_TRUE(r.history.back().wot_limited);
}

TEST(Vehicle, AcceleratesAtTheCommandedRateWhileTorqueAllows) {
  MobilityRunParams p = Scene(0.0);
  p.duration = 8.0;
  MobilityRun s(p);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  // after the controller's start-up, v follows 1 m/s^2: compare the slope over t in [3, 8] s
  double v3 = 0, v8 = 0;
  for (const auto& h : r.history) {
    if (std::abs(h.t - 3.0) < 1e-6 + 0.005) v3 = h.speed;
    if (std::abs(h.t - 8.0) < 1e-6 + 0.005) v8 = h.speed;
  }
  EXPECT_NEAR((v8 - v3) / 5.0, 1.0, 0.03);
}

// A coupling interval of n exchanges with the terrain every n-th step and holds the wrenches in
// between; at rest on the road the held wrenches still carry the weight.
TEST(Vehicle, CouplingIntervalExchangesEveryNthStepAndHoldsTheWrenches) {
  MobilityRunParams p = Scene(0.0);
  p.coupling_interval = 4;
  p.duration = 0.5;
  MobilityRun s(p);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.exchanges, r.steps / 4 + 1);  // the opening exchange, then steps 4, 8, ...
  EXPECT_EQ(s.sim().last_exchange_step(), r.steps - r.steps % 4);
  const Vehicle& v = s.vehicle();
  double total = 0;
  for (int i = 0; i < 4; ++i) total += v.WheelLoad(i);
  EXPECT_NEAR(total, v.system().TotalMass() * 9.81, 0.01 * v.system().TotalMass() * 9.81);
}

TEST(Vehicle, TimeStepAboveTheCriticalOneIsRefused) {
  MobilityRunParams p = Scene(0.0);
  MobilityRun probe(p);
  p.time_step = 1.5 * probe.sim().limit().dt_crit;
  try {
    MobilityRun s(p);
    FAIL() << "a step above the critical one was accepted";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("time_step"), std::string::npos) << m;
    EXPECT_NE(m.find("critical step"), std::string::npos) << m;
    EXPECT_NE(m.find("road_slope.yaml"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace dem_mobility::core
