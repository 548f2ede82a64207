// The 33-body vehicle against statics and the power balance on a grade.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/mobility/mobility_run.h"
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

namespace fs = std::filesystem;

// A scratch copy of the HMMWV folder whose driveline.yaml sets the centre and axle differentials.
class VehicleWithDifferentials {
 public:
  VehicleWithDifferentials(const std::string& centre, const std::string& axles) {
    dir_ = fs::temp_directory_path() / ("dm_veh_" + std::to_string(::getpid()) + "_" + centre + "_" + axles);
    fs::remove_all(dir_);
    fs::copy(DM_CONFIG_DIR "/vehicles/hmmwv", dir_, fs::copy_options::recursive);
    const fs::path p = dir_ / "driveline.yaml";
    std::stringstream ss;
    ss << std::ifstream(p).rdbuf();
    std::string s = ss.str();
    Replace(&s, "\ncentre_differential: locked\n", "\ncentre_differential: " + centre + "\n");
    Replace(&s, "\naxle_differentials: open\n", "\naxle_differentials: " + axles + "\n");
    std::ofstream(p) << s;
  }
  ~VehicleWithDifferentials() { fs::remove_all(dir_); }
  std::string file() const { return (dir_ / "vehicle.yaml").string(); }

 private:
  static void Replace(std::string* s, const std::string& from, const std::string& to) {
    const auto pos = s->find(from);
    DM_DEMAND(pos != std::string::npos);
    s->replace(pos, from.size(), to);
  }
  fs::path dir_;
};

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

// Steady speed where WOT(w) G / r = m g (sin th + c_rr cos th), w = v / (G r): the highest drive-shaft
// speed at which WOT still meets the load (the plateau a vehicle accelerating from below reaches),
// found by stepping down from the table's last speed and bisecting the step, independent of the
// simulation.
double PowerBalanceSpeed(const PowertrainParams& pt, double m, double r, double G, double th, double c_rr) {
  const double torque = m * 9.81 * r * G * (std::sin(th) + c_rr * std::cos(th));
  const double step = 0.5;  // [rad/s], finer than the table's rows
  double hi = pt.wot.x().back();
  while (hi > step && pt.wot(hi - step) < torque) hi -= step;
  double lo = hi - step;
  DM_DEMAND(pt.wot(lo) >= torque);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pt.wot(mid) >= torque ? lo : hi) = mid;
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

// The paper's driveline (one drive shaft driving both axles, centre locked) climbs a 30 deg paved
// grade at full throttle: each axle pulls as its own load allows, so the rear axle, loaded by the
// grade, carries what the front cannot. The whole 40 s (the plateau from about 17 s), the driver
// keeping to the start line (unsteered it would leave the 8 m road at about 25 s: next test).
TEST(Vehicle, ClimbsThirtyDegreesAtThePowerBalanceSpeedWithTheCentreLocked) {
  const double grade = 30.0;
  MobilityRunParams p = Scene(grade);  // 40 s, the driver keeping to the start line
  ASSERT_TRUE(p.driver.steer);
  MobilityRun s(p);
  ASSERT_EQ(s.vehicle().spec().driveline.centre_differential, Differential::kLocked);  // the shipped file
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.smg.status, "steady");
  const Vehicle& v = s.vehicle();
  const double c_rr = YamlReader::Load(p.terrain_file).Child("contact").Double("c_rr");
  const double expected = PowerBalanceSpeed(v.powertrain(), v.system().TotalMass(), v.tire().radius,
                                            v.driveline_reduction(), grade * M_PI / 180.0, c_rr);
  EXPECT_NEAR(r.smg.value, expected, 0.05 * expected);
  EXPECT_TRUE(r.history.back().wot_limited);
  // on its line the whole way: within a quarter of a tire's width of it, heading within 1 deg
  double y = 0.0, heading = 0.0;
  for (const MobilitySample& h : r.history) {
    y = std::max(y, std::abs(h.y));
    heading = std::max(heading, std::abs(h.heading));
  }
  std::printf("off its line at most %.4f m (a quarter of a tire's width: %.4f m), heading %.3f deg\n", y,
              0.25 * v.tire().width, heading * 180.0 / M_PI);
  EXPECT_LT(y, 0.25 * v.tire().width);
  EXPECT_LT(heading, M_PI / 180.0);
}

// Without the driver's steering the rigid tires' lateral forces (the wheels toe under load) turn
// the vehicle off its line on 30 deg; it leaves the 8 m road and the run stops with an error that
// names the road and its width instead of going on off the road.
TEST(Vehicle, UnsteeredOnThirtyDegreesItLeavesTheRoadAndTheRunStopsSayingSo) {
  MobilityRunParams p = Scene(30.0);
  p.driver.steer = false;
  const MobilityRunResult r = MobilityRun(p).Run();
  EXPECT_NE(r.error.find("off the road"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("`width`"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("rigid_road.yaml"), std::string::npos) << r.error;
  ASSERT_FALSE(r.history.empty());
  EXPECT_GT(std::abs(r.history.back().y), 2.0);  // drifted sideways by metres before it stopped
}

// With an open centre differential the drive shaft gives both axles the same torque, so the front
// axle (the lighter one on a grade) caps the traction: on 30 deg its wheels spin and the vehicle
// does not get up the grade at the speed the locked one makes.
TEST(Vehicle, AnOpenCentreDifferentialDoesNotClimbThirtyDegrees) {
  const double grade = 30.0;
  const VehicleWithDifferentials open("open", "open");
  MobilityRunParams p = Scene(grade);
  p.vehicle_file = open.file();
  p.duration = 22.0;
  MobilityRun s(p);
  ASSERT_EQ(s.vehicle().spec().driveline.centre_differential, Differential::kOpen);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  const Vehicle& v = s.vehicle();
  const double c_rr = YamlReader::Load(p.terrain_file).Child("contact").Double("c_rr");
  const double expected = PowerBalanceSpeed(v.powertrain(), v.system().TotalMass(), v.tire().radius,
                                            v.driveline_reduction(), grade * M_PI / 180.0, c_rr);
  EXPECT_TRUE(r.smg.status == "no_go" || r.smg.value < 0.5 * expected)
      << r.smg.status << " at " << r.smg.value << " m/s";
  // the cause: the front wheels spin, turning far faster than the vehicle moves
  const double front_rim = 0.5 * (v.WheelSpeed(kFrontLeft) + v.WheelSpeed(kFrontRight)) * v.tire().radius;
  EXPECT_GT(front_rim, std::abs(v.ForwardSpeed()) + 2.0) << "front rim " << front_rim << " m/s, vehicle "
                                                         << v.ForwardSpeed() << " m/s";
}

// On a lift (chassis held, wheels hanging): the drive shaft turns, a moment holds back the front
// left wheel. Each differential setting gives its own kinematics, compared on the angles turned
// (the speeds carry the driveline's torsional ringing): open, the carrier turns through the mean of
// its outputs; locked, each output turns with it.
TEST(Vehicle, DifferentialSettingsSetWhichShaftsTurnTogether) {
  struct Case {
    Differential centre, axles;
  };
  for (const Case& c : {Case{Differential::kLocked, Differential::kOpen}, Case{Differential::kOpen, Differential::kOpen},
                        Case{Differential::kLocked, Differential::kLocked}}) {
    VehicleSpec spec = VehicleSpec::Load(kHmmwv);
    spec.driveline.centre_differential = c.centre;
    spec.driveline.axle_differentials = c.axles;
    std::unique_ptr<Vehicle> v = Vehicle::Build(spec, Eigen::Vector3d(0, 0, 1.0));
    MultibodySystem& sys = v->system();
    sys.mutable_body(v->chassis()).fixed = true;
    sys.Finalize(0.5 * sys.CriticalTimeStep().dt_crit);
    v->SetDriveTorqueRequest(100.0);
    WheelWrench hold;
    hold.moment = Eigen::Vector3d(0, -150.0, 0);  // against forward spin (+y)
    v->SetWheelWrench(kFrontLeft, hold);
    double shaft = 0.0, wheel[4] = {0, 0, 0, 0};  // angles turned relative to the housings [rad]
    while (sys.time() < 1.0) {
      sys.Step();
      shaft += sys.dt() * v->DriveShaftSpeed();
      for (int i = 0; i < 4; ++i) wheel[i] += sys.dt() * v->WheelSpeed(i);
    }
    const double carrier = v->driveline_reduction() * shaft;  // each carrier's angle, centre locked
    const double fl = wheel[kFrontLeft], fr = wheel[kFrontRight], rl = wheel[kRearLeft], rr = wheel[kRearRight];
    // the elastic twist of the penalty chain from the shaft to a wheel (final drive, differential,
    // two CV joints: each twisted by its torque of a few hundred N m / k = 1e5 N m/rad, a few mrad)
    const double tol = 0.05;
    SCOPED_TRACE(::testing::Message() << "centre " << (c.centre == Differential::kOpen ? "open" : "locked")
                                      << ", axles " << (c.axles == Differential::kOpen ? "open" : "locked")
                                      << ": shaft x reduction " << carrier << " rad, wheels " << fl << " " << fr << " "
                                      << rl << " " << rr << " rad");
    ASSERT_GT(carrier, 100.0 * tol);
    if (c.axles == Differential::kOpen) {
      EXPECT_LT(fl, fr - 0.5 * carrier);  // the held wheel lags, its partner runs ahead
      if (c.centre == Differential::kLocked) {
        EXPECT_NEAR(0.5 * (fl + fr), carrier, tol);
        EXPECT_NEAR(0.5 * (rl + rr), carrier, tol);
      } else {  // the carriers turn through the shaft's angle on average; the free rear axle runs away
        EXPECT_NEAR(0.25 * (fl + fr + rl + rr), carrier, tol);
        EXPECT_GT(0.5 * (rl + rr), 1.25 * carrier);
      }
    } else {
      for (double w : {fl, fr, rl, rr}) EXPECT_NEAR(w, carrier, tol);
    }
  }
}

// The locked centre's couplings join a pinion and the drive shaft: the guard's mode for each is the
// two spins against each other, omega^2 = k (1/I_pinion + 1/I_shaft), and the step the vehicle runs
// at respects it.
TEST(Vehicle, LockedCentreCouplingsAreInTheTimeStepGuard) {
  const VehicleSpec spec = VehicleSpec::Load(kHmmwv);
  const std::unique_ptr<Vehicle> v = Vehicle::Build(spec, Eigen::Vector3d::Zero());
  const MultibodySystem& sys = v->system();
  const double i_pinion = spec.driveline.pinion.inertia(0, 0);
  const double i_shaft = 0.5 * spec.driveline.drive_shaft.mass * std::pow(spec.driveline.drive_shaft.radius, 2);
  const double k = spec.rotational_penalty.k, c = spec.rotational_penalty.c;
  const double omega = std::sqrt(k * (1.0 / i_pinion + 1.0 / i_shaft));
  const double dt = CriticalStep(omega, c * omega / (2.0 * k));
  int found = 0;
  for (const RotationalCoupling& rc : sys.couplings) {
    if (rc.name != "drive_shaft_front_pinion" && rc.name != "drive_shaft_rear_pinion") continue;
    ++found;
    EXPECT_NEAR(rc.Stiffness(sys.bodies()).omega, omega, 1e-9 * omega) << rc.name;
  }
  EXPECT_EQ(found, 2);
  EXPECT_LE(sys.CriticalTimeStep().dt_crit, dt);
}

TEST(Vehicle, AcceleratesAtTheCommandedRateWhileTorqueAllows) {
  MobilityRunParams p = Scene(0.0);
  p.duration = 8.0;
  MobilityRun s(p);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  // after the controller's start-up, v follows 1 m/s^2: compare the slope over t in [3, 8] s
  // (the samples nearest to 3 s and to the end: the sample period is a whole number of steps)
  const auto nearest = [&](double t) {
    const MobilitySample* best = &r.history.front();
    for (const auto& h : r.history)
      if (std::abs(h.t - t) < std::abs(best->t - t)) best = &h;
    return best;
  };
  const MobilitySample *a = nearest(3.0), *b = nearest(8.0);
  EXPECT_NEAR(a->t, 3.0, 0.02);
  EXPECT_NEAR(b->t, 8.0, 0.02);
  EXPECT_NEAR((b->speed - a->speed) / (b->t - a->t), 1.0, 0.03);
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

// The vehicle's energy ledger (Vehicle::Energy, followed by the run): the engine's work is the
// integral of its torque times the drive shaft's speed (checked against the history's own 100 Hz
// samples), the road's rolling resistance takes c_rr m g per metre of it, and what is left went to
// the dampers, brakes and differentials: never negative.
TEST(VehicleEnergy, TheEngineGivesTheRoadsRollingResistanceTakesTheDampersNeverGive) {
  MobilityRunParams p = Scene(0.0);
  p.duration = 8.0;
  MobilityRun s(p);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  const EnergyReport& e = r.vehicle_energy;
  double engine = 0.0;
  for (size_t i = 1; i < r.history.size(); ++i) {
    const MobilitySample &a = r.history[i - 1], &b = r.history[i];
    engine += 0.5 * (b.t - a.t) * (a.drive_torque * a.drive_shaft_speed + b.drive_torque * b.drive_shaft_speed);
  }
  EXPECT_GT(engine, 1e5);
  EXPECT_NEAR(e.exchanged, engine, 0.01 * engine);
  const YamlReader road = YamlReader::Load(DM_CONFIG_DIR "/terrains/rigid_road.yaml");
  const double c_rr = road.Child("contact").Double("c_rr");
  const double weight = s.vehicle().system().TotalMass() * 9.81, distance = r.history.back().x;
  EXPECT_GT(distance, 20.0);
  // The same run without rolling resistance: the road's work differs by the resistance's, c_rr m g
  // per metre (the rest of what the road takes, the same in both, is the rigid polygonal tire's
  // vertices striking the road, damped, and the tires' slip)
  MobilityRunParams q = p;
  q.terrain_overrides.push_back("contact.c_rr=0");
  MobilityRun free(q);
  const MobilityRunResult f = free.Run();
  ASSERT_TRUE(f.error.empty()) << f.error;
  const double rolling = c_rr * weight * distance, difference = f.vehicle_energy.wall_work - e.wall_work;
  std::printf("the road's work %.0f J, %.0f J without rolling resistance: %.0f J apart, c_rr m g d = %.0f J\n",
              -e.wall_work, -f.vehicle_energy.wall_work, difference, rolling);
  EXPECT_NEAR(difference, rolling, 0.03 * rolling);
  EXPECT_GT(e.dissipated, 0.0);
  EXPECT_GE(r.vehicle_ledger.least, -1e-3 * r.vehicle_ledger.Scale());
  EXPECT_DOUBLE_EQ(r.vehicle_ledger.dissipated, e.dissipated);  // the watch starts at the run's first step
  EXPECT_GT(r.vehicle_ledger.samples, 800);
}

// A vehicle set rolling (start_speed): every wheel turns at v / r and every shaft and gear as its
// couplings and CV joints require, so nothing is strained at the start; dropped from 0.5 m onto
// the road, it lands and settles with its ledger never below zero.
TEST(VehicleEnergy, ARollingStartStrainsNothingAndADropDissipates) {
  MobilityRunParams p = Scene(0.0);
  p.start_speed = 10.0;
  p.settle_time = 0.0;
  p.driver.full_throttle = true;
  p.duration = 0.5;
  MobilityRun s(p);
  const Vehicle& v = s.vehicle();
  const double w = 10.0 / v.tire().radius;
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(v.WheelSpeed(i), w, 1e-9 * w) << i;
  EXPECT_NEAR(v.DriveShaftSpeed(), w / v.driveline_reduction(), 1e-9 * w / v.driveline_reduction());
  for (const RotationalCoupling& c : v.system().couplings) EXPECT_NEAR(c.Rate(v.system().bodies()), 0.0, 1e-9 * w) << c.name;
  EXPECT_NEAR(v.ForwardSpeed(), 10.0, 1e-12);
  const MobilityRunResult r = s.Run();
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_NEAR(r.history.front().speed, 10.0, 0.05);  // no start-up jolt
  EXPECT_GE(r.vehicle_ledger.least, -1e-3 * r.vehicle_ledger.Scale());

  MobilityRunParams d = Scene(0.0);
  d.start_height = 0.5;
  d.settle_time = 1.5;
  d.duration = 0.1;
  MobilityRun drop(d);
  const double z0 = drop.vehicle().ChassisFramePosition().z();
  const MobilityRunResult q = drop.Run();
  ASSERT_TRUE(q.error.empty()) << q.error;
  const double fall = z0 - drop.vehicle().ChassisFramePosition().z();
  EXPECT_NEAR(fall, 0.5, 0.05);  // landed and settled where it would have stood
  EXPECT_LT(q.vehicle_energy.wall_work, 0.0);  // the road took energy (its dampers and friction)
  EXPECT_GT(q.vehicle_ledger.dissipated, 0.0);
  EXPECT_GE(q.vehicle_ledger.least, -1e-3 * q.vehicle_ledger.Scale());
  // what the drop lost: the weight times the fall, less the little left in motion and springs
  const double lost = -q.vehicle_energy.wall_work + q.vehicle_ledger.dissipated;
  const double mgh = drop.vehicle().system().TotalMass() * 9.81 * fall;
  EXPECT_NEAR(lost, mgh, 0.05 * mgh);
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
