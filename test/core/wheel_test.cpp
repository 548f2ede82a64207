// The tire on DEM soil: the tire's soil surface, the binned tire contact against the brute-force
// triangle scan, action and reaction, the dem_soil terrain's exchange, a small moving soil patch,
// the single-wheel rig's input checks. (The rig's physics runs for minutes: wheel_rig_test.cpp.)
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <utility>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/result_file.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/dem/dem_system.h"
#include "dem_mobility/core/geometry/tire_geometry.h"
#include "dem_mobility/core/scenes/single_wheel.h"
#include "dem_mobility/core/terrain/dem_soil.h"
#include "dem_mobility/core/terrain/soil_patch.h"
#include "dem_mobility/core/vehicle/vehicle_spec.h"
#include "dem_test_soils.h"

namespace dem_mobility::core {
namespace {

using Eigen::Vector3d;

TireGeometry PaperTire() { return TireGeometry::Read(YamlReader::Load(DM_CONFIG_DIR "/vehicles/hmmwv/tire.yaml")); }

TEST(TireSurface, IsClosedButForTheHubAndHasThePapersTriangles) {
  const TireGeometry t = PaperTire();
  EXPECT_GT(t.mesh.faces.size(), 6600u);  // the paper: more than 6,600 triangles on the tread
  // ours (tire.yaml, docs/single-wheel.md): 144 x 24 tread vertices, 144 x 23 x 2 triangles; the
  // soil surface adds 4 rings of 144 on each sidewall and their 2 x 4 x 144 x 2 triangles
  EXPECT_EQ(t.mesh.vertices.size(), 144u * 24u);
  EXPECT_EQ(t.mesh.faces.size(), 144u * 23u * 2u);
  EXPECT_EQ(t.soil_mesh.vertices.size(), 144u * 24u + 2u * 4u * 144u);
  EXPECT_EQ(t.soil_mesh.faces.size(), 144u * 23u * 2u + 2u * 4u * 144u * 2u);
  // every edge is shared by two triangles, except the two rim circles (the hub's hole)
  std::map<std::pair<int, int>, int> edges;
  for (const auto& f : t.soil_mesh.faces)
    for (int k = 0; k < 3; ++k) ++edges[{std::min(f[k], f[(k + 1) % 3]), std::max(f[k], f[(k + 1) % 3])}];
  int open = 0;
  for (const auto& e : edges) {
    EXPECT_LE(e.second, 2);
    if (e.second == 1) {
      ++open;
      for (int v : {e.first.first, e.first.second}) {
        const Vector3d p = t.soil_mesh.vertices[v];
        EXPECT_NEAR(std::hypot(p.x(), p.z()), t.rim_radius, 1e-12);
      }
    }
  }
  EXPECT_EQ(open, 2 * t.n_circ);
  for (const Vector3d& v : t.soil_mesh.vertices) {
    EXPECT_LE(std::hypot(v.x(), v.z()), t.radius + 1e-12);
    EXPECT_LE(std::abs(v.y()), 0.5 * t.width + 1e-12);
  }
}

TEST(TireSurface, LugsStandProudOfTheCarcassOnTheirShareOfTheCircumference) {
  TireLugs lugs;
  lugs.count = 12;
  lugs.height = 0.02;
  lugs.fraction = 0.25;
  const TireGeometry t = TireGeometry::Make(0.485, 0.254, 0.0, 144, 8, lugs);
  int on_lug = 0;
  for (int c = 0; c < t.n_circ; ++c) {
    const Vector3d v = t.Vertex(c, t.n_lat / 2);
    const double r = std::hypot(v.x(), v.z());
    EXPECT_TRUE(std::abs(r - 0.485) < 1e-12 || std::abs(r - 0.465) < 1e-12) << r;
    on_lug += std::abs(r - 0.485) < 1e-12;
  }
  EXPECT_EQ(on_lug, 144 / 4);
  EXPECT_THROW(TireGeometry::Make(0.485, 0.254, 0.0, 40, 8, lugs), ConfigError);  // 12 lugs need 48 columns
}

// A tire rolling forward and sinking at once through a small bed of particles under gravity,
// with its triangles binned or scanned.
struct RollResult {
  std::vector<Vector3d> x, v;
  std::vector<Vector3d> force, moment;
  int max_contacts = 0;
  long wall_builds = 0, candidates = 0;
  bool binned = false;
};

RollResult Roll(bool bins, int steps) {
  SoilParams soil = Nominal();
  soil.diameter = 0.06;
  DemSettings st;
  st.wall_bins = bins;
  st.max_overlap = 0.4;  // as the soil scenes: room for a particle dropped in against the tire
  DemSystem s(soil, st);
  const TireGeometry tire = PaperTire();
  DemWall w;
  w.name = "tire";
  w.mesh = tire.soil_mesh;
  w.fast = true;
  const Vector3d c0(-1.2, 0.0, 0.485 + 0.10);  // behind the bed, its bottom 10 cm up
  w.position = c0;
  const int tw = s.AddWall(w);
  s.AddWall(MakeQuadWall("floor", {-1, -0.4, 0}, {2, 0, 0}, {0, 0.8, 0}));
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 3; ++k)
        s.AddParticle(Vector3d(-0.7 + 0.061 * i + 0.003 * (j % 2), -0.22 + 0.061 * j, 0.031 + 0.061 * k));
  const double dt = 8e-5;
  s.Finalize(dt);
  RollResult r;
  r.binned = s.wall_contacts().binned(tw);
  const double v = 3.0, omega = 3.0 / 0.4, sink = 0.06;
  for (int n = 1; n <= steps; ++n) {
    const double t = n * dt;
    DemWall& tw_ = s.mutable_wall(tw);
    tw_.position = c0 + Vector3d(v * t, 0.0, -sink * t / (steps * dt));
    tw_.rotation = Eigen::AngleAxisd(omega * t, Vector3d::UnitY()).toRotationMatrix();
    tw_.velocity = Vector3d(v, 0.0, -sink / (steps * dt));
    tw_.angular_velocity = Vector3d(0.0, omega, 0.0);
    tw_.wrench_point = tw_.position;
    // now and then a particle dropped in just ahead of the tire: its first steps try the tire's
    // triangles before any build lists it (the binned wall: its cell's)
    if (n % 400 == 0) s.AddParticle(tw_.position + Vector3d(0.5, 0.03 * (n % 3), -0.1));  // touching it
    s.Step();
    r.force.push_back(s.wall(tw).force);
    r.moment.push_back(s.wall(tw).moment);
    r.max_contacts = std::max(r.max_contacts, s.wall(tw).contacts);
    r.candidates = std::max(r.candidates, s.wall_candidates());
  }
  r.x = s.positions();
  r.v = s.velocities();
  r.wall_builds = s.wall_builds();
  return r;
}

TEST(TireContact, BinnedTrianglesGiveTheScansForcesBitForBit) {
  const int steps = 2500;
  const RollResult binned = Roll(true, steps), scan = Roll(false, steps);
  ASSERT_TRUE(binned.binned);
  ASSERT_FALSE(scan.binned);
  EXPECT_GT(binned.max_contacts, 20);  // the tire did plough through the bed
  EXPECT_GT(binned.wall_builds, 5);    // and its candidates were rebuilt as it rolled
  EXPECT_EQ(binned.candidates, scan.candidates);
  for (int n = 0; n < steps; ++n) {
    ASSERT_EQ(binned.force[n], scan.force[n]) << "step " << n;
    ASSERT_EQ(binned.moment[n], scan.moment[n]) << "step " << n;
  }
  for (size_t i = 0; i < binned.x.size(); ++i) {
    EXPECT_EQ(binned.x[i], scan.x[i]) << "particle " << i;
    EXPECT_EQ(binned.v[i], scan.v[i]) << "particle " << i;
  }
}

TEST(TireContact, TheParticlesGetMinusTheTiresForceEveryStep) {
  // no gravity and no other wall: the particles' total force is the tire's reaction (the pair
  // forces cancel in pairs, to round-off)
  SoilParams soil = Nominal();
  soil.diameter = 0.06;
  DemSystem s(soil, DemSettings());
  s.set_gravity(Vector3d::Zero());
  const TireGeometry tire = PaperTire();
  DemWall w;
  w.name = "tire";
  w.mesh = tire.soil_mesh;
  w.fast = true;
  w.position = Vector3d(-0.6, 0.0, 0.0);
  const int tw = s.AddWall(w);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) s.AddParticle(Vector3d(0.0585 * i, -0.15 + 0.0585 * j, -0.49 + 0.0585 * k));
  const double dt = 8e-5;
  s.Finalize(dt);
  int touched = 0;
  for (int n = 1; n <= 3000; ++n) {
    DemWall& t = s.mutable_wall(tw);
    t.velocity = Vector3d(1.5, 0.0, 0.0);
    t.angular_velocity = Vector3d(0.0, 2.0, 0.0);
    t.position += dt * t.velocity;
    t.rotation = Eigen::AngleAxisd(2.0 * dt, Vector3d::UnitY()).toRotationMatrix() * t.rotation;
    t.wrench_point = t.position;
    s.Step();
    Vector3d sum = Vector3d::Zero();
    double scale = 0.0;
    for (int id = 0; id < s.size(); ++id) {
      sum += s.force(id);
      scale += s.force(id).norm();
    }
    const Vector3d f = s.wall(tw).force;
    if (s.wall(tw).contacts > 0) ++touched;
    ASSERT_LE((sum + f).norm(), 1e-12 * std::max(scale, 1.0)) << "step " << n << ": particles " << sum.transpose()
                                                              << ", tire " << f.transpose();
  }
  EXPECT_GT(touched, 500);
}

// A small prepared bin for the exchange tests (d = 0.1 m, seconds)
std::string TinyBin() {
  return "model: dem_soil\n"
         "soil: " DM_CONFIG_DIR "/soils/nominal_clay.yaml\n"
         "fidelity: tiny\n"
         "cohesion_factor: 1.5\n"
         "friction: 0.1\n"
         "threads: 1\n"
         "lid: {pressure: 33.3e3, speed: 0.5, release_time: 0.2}\n"
         "levels:\n"
         "  tiny: {particle_diameter: 0.1, length: 1.6, width: 0.6, soil_depth: 0.4, time_step: 1.2e-4,"
         " settle_time: 0.3, hold_time: 0.05}\n";
}

TEST(DemSoilTerrain, AdvancesInWholeSoilStepsAndReturnsTheMeanReaction) {
  const YamlReader y = YamlReader::FromString(TinyBin(), "tiny_bin.yaml");
  TerrainVehicle v;
  v.tire = PaperTire();
  v.wheels = 1;
  auto model = MakeDemSoilTerrain(y, v);
  auto* soil = dynamic_cast<DemSoilTerrain*>(model.get());
  ASSERT_NE(soil, nullptr);
  EXPECT_EQ(model->description().model, "dem_soil");
  const double h = 1.2e-4, surface = soil->bin().surface_height();
  // the prepared soil is moved so that the highest particle of its interior (1.5 d and more from
  // the walls) tops out at z = 0, where a vehicle starts with its tires touching: no tire starts
  // inside a particle; the surface (the mean top of the highest particles) a little below, the
  // floor under it by the soil's depth
  double top = -1.0;
  soil->bin().dem().ForEachParticle([&](int, const Vector3d& x, const Vector3d&) {
    if (x.x() > 0.15 && x.x() < 1.45 && std::abs(x.y()) < 0.15) top = std::max(top, x.z() + 0.05);
  });
  EXPECT_NEAR(top, 0.0, 1e-12);
  EXPECT_LE(surface, 0.0);
  EXPECT_GT(surface, -0.1);  // within a diameter
  EXPECT_LT(soil->bin().floor_z(), -0.2);
  // the tire lowered 3 cm into the soil at 0.25 m/s, then held there
  WheelState s;
  std::vector<WheelWrench> wr;
  const long steps0 = soil->bin().dem().step_count();
  for (int k = 0; k < 400; ++k) {
    const double t = 3 * h * k, v = t < 0.12 ? -0.25 : 0.0;
    s.position = Vector3d(0.8, 0.0, surface + 0.485 - 0.25 * std::min(t, 0.12));
    s.velocity = Vector3d(0.0, 0.0, v);
    model->Synchronize(k, t, {s});
    model->GetWrenches(&wr);
    model->Advance(3 * h);
  }
  EXPECT_EQ(soil->bin().dem().step_count() - steps0, 1200);
  model->GetWrenches(&wr);
  ASSERT_EQ(wr.size(), 1u);
  EXPECT_GT(wr[0].force.z(), 0.0);  // the soil pushes the tire up
  EXPECT_GT(wr[0].normal_force, 0.0);
  EXPECT_GT(wr[0].contacts, 0);
  EXPECT_NEAR(wr[0].sinkage, 0.25 * 0.12, 1e-9);
  EXPECT_GT(wr[0].stiffness, 0.0);
  EXPECT_THROW(model->Advance(2.5 * h), SimulationError);  // not a whole number of soil steps
  EXPECT_THROW(model->Synchronize(401, 1.0, {s, s}), std::exception);
}

// A small moving soil patch, small enough for the sanitizer build (scripts/sanitize.sh; the patch's
// own tests, soil_patch_test, take minutes even at full speed): the tiny level in its shortest box
// (6 m), soil only in the narrowest strips under the wheel tracks (0.46 m: a tire and two particle
// diameters), settled for 0.05 s and released from the lid in 0.1 s. Four wheels ride
// 0.5 m above the soil at 8 m/s for 1.5 m beyond where the patch starts to follow them: it follows,
// removes the soil its sphere leaves behind and lays it down again ahead, and the particle count
// never changes.
TEST(DemSoilTerrain, ASmallPatchFollowsTheWheelsAndReEmitsKeepingItsCount) {
  const VehicleSpec spec = VehicleSpec::Load(DM_CONFIG_DIR "/vehicles/hmmwv/vehicle.yaml");
  std::unique_ptr<TerrainModel> m =
      LoadTerrainModel(DM_CONFIG_DIR "/terrains/soil_patch.yaml", TerrainVehicleOf(spec),
                       {"fidelity=tiny", "threads=1", "cone_index=100", "track_strip_width=0.46", "levels.tiny.length=6",
                        "levels.tiny.settle_time=0.05", "lid.release_time=0.1", "patch.check_window=[0.3, 0.7]"});
  auto* t = dynamic_cast<DemSoilTerrain*>(m.get());
  ASSERT_NE(t, nullptr);
  ASSERT_NE(t->patch(), nullptr);
  const SoilPatch& patch = *t->patch();
  const int n0 = t->bin().dem().num_alive();
  const double h = t->description().time_step, r = t->bin().tire().radius, v = 8.0;
  const double x_end = patch.sphere_centre().x() + 1.5;
  const double xs[4] = {1.65, 1.65, -1.65, -1.65}, ys[4] = {0.9, -0.9, 0.9, -0.9};
  std::vector<WheelState> wheels(4);
  std::vector<WheelWrench> w;
  double x = 0.0;
  for (long k = 0; x < x_end; ++k) {
    for (int i = 0; i < 4; ++i) {
      wheels[i].position = Vector3d(x + xs[i], ys[i], 1.0);
      wheels[i].velocity = Vector3d(v, 0.0, 0.0);
      wheels[i].angular_velocity = Vector3d(0.0, v / r, 0.0);
    }
    t->Synchronize(k, k * h, wheels);
    t->GetWrenches(&w);
    t->Advance(h);
    ASSERT_EQ(t->bin().dem().num_alive(), n0) << "step " << k;
    x += v * h;
  }
  const PatchStats& s = patch.stats();
  EXPECT_TRUE(s.following);
  // the sphere moved 1.5 m: the soil of about 1.5 m of the two strips (some 500 particles) left it
  EXPECT_GT(s.reemitted, 300);
  EXPECT_GT(s.copies, 0);
  EXPECT_NEAR(patch.sphere_centre().x(), x, 1e-9);  // it follows the wheels' centroid
  std::printf("%d particles; re-emitted %ld (strays %ld), copies %d\n", n0, s.reemitted, s.strays, s.copies);
}

std::string SceneFile() { return DM_CONFIG_DIR "/scenes/single_wheel.yaml"; }

void ExpectRefused(const std::vector<std::string>& overrides, const std::string& key) {
  try {
    SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), overrides));
    ADD_FAILURE() << "accepted " << overrides.back();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("single_wheel.yaml"), std::string::npos) << e.what();
  }
}

TEST(SingleWheelConfig, RefusesBadInputNamingTheKey) {
  EXPECT_NO_THROW(SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"fidelity=tiny"})));
  ExpectRefused({"wheel.slip=1.5"}, "wheel.slip");
  ExpectRefused({"wheel.slip=-1.01"}, "wheel.slip");
  ExpectRefused({"wheel.slip=1"}, "wheel.slip");  // an infinite wheel speed
  ExpectRefused({"wheel.drive=torque", "wheel.torque=2e5"}, "wheel.torque");
  ExpectRefused({"wheel.drive=skid"}, "wheel.drive");
  ExpectRefused({"fidelity=tiny", "levels.tiny.width=0.4"}, "levels.tiny.width");  // the tire is 0.254 m + 2 x 0.1 m
  ExpectRefused({"carriage.window=[0.8, 3.0]"}, "carriage.window");
  ExpectRefused({"carriage.start_x=0.3"}, "carriage.start_x");
  ExpectRefused({"cohesion_factor=41"}, "cohesion_factor");
  ExpectRefused({"wheel.load_mass=-3"}, "wheel.load_mass");
  ExpectRefused({"fidelity=huge"}, "fidelity");
  ExpectRefused({"wheel.sliip=0.1"}, "sliip");
  // slips at the ends of the range that make sense are taken
  EXPECT_NO_THROW(SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"wheel.slip=-1"})));
  EXPECT_NO_THROW(SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"wheel.slip=0.99"})));
}

TEST(SingleWheelConfig, UsesTheCalibrationTableOfItsParticleSizeOnly) {
  // coarse (0.06 m): the table made at 0.06 m turns CI into f and is named in the result
  const SingleWheelParams coarse =
      SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"fidelity=coarse", "cone_index=100"}));
  ASSERT_TRUE(coarse.bin.strength.calibration);
  EXPECT_DOUBLE_EQ(coarse.bin.strength.calibration->particle_diameter, 0.06);
  EXPECT_DOUBLE_EQ(coarse.bin.strength.cohesion_factor, coarse.bin.strength.calibration->CohesionFactor(100.0));
  ResultFile r(SceneFile(), "single_wheel");
  coarse.bin.Describe(&r);
  EXPECT_NE(r.Text().find("calibration_table"), std::string::npos);
  EXPECT_NE(r.Text().find("calibration_error_vs_finest"), std::string::npos);
  // tiny (0.1 m): the table made at 0.1 m (level tiny_cal of the cone scene)
  const SingleWheelParams tiny =
      SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"fidelity=tiny", "cone_index=100"}));
  ASSERT_TRUE(tiny.bin.strength.calibration);
  EXPECT_DOUBLE_EQ(tiny.bin.strength.calibration->particle_diameter, 0.1);
  EXPECT_DOUBLE_EQ(tiny.bin.strength.cohesion_factor, tiny.bin.strength.calibration->CohesionFactor(100.0));
  // fine (0.04 m): no table is made at that size; a cone index is refused, f runs with its CI unknown
  ExpectRefused({"fidelity=fine", "cone_index=100"}, "particle_diameter");
  const SingleWheelParams fine =
      SingleWheelParams::Read(YamlReader::LoadWithOverrides(SceneFile(), {"fidelity=fine", "cohesion_factor=2"}));
  EXPECT_FALSE(fine.bin.strength.calibration);
  EXPECT_FALSE(std::isfinite(fine.bin.strength.ConeIndex()));
  EXPECT_NE(fine.bin.strength.no_table_reason.find("0.04"), std::string::npos) << fine.bin.strength.no_table_reason;
}

TEST(SingleWheelRig, ALoadTheSoilCannotCarryIsReportedSunk) {
  // 30 t on a weak tiny bed: the wheel goes through to the floor; the run ends 'sunk' with its result
  const YamlReader y = YamlReader::LoadWithOverrides(
      SceneFile(), {"fidelity=tiny", "threads=1", "cohesion_factor=0.05", "wheel.load_mass=30000"});
  SingleWheelRig rig(SingleWheelParams::Read(y));
  RunSoilRig(rig);
  EXPECT_TRUE(rig.done());
  EXPECT_TRUE(rig.sunk());
  EXPECT_TRUE(rig.error().empty()) << rig.error();
  const ResultFile r = rig.Report();
  EXPECT_EQ(r.status(), "sunk");
  EXPECT_NE(r.error().find("sank"), std::string::npos) << r.error();
}

TEST(SingleWheelRig, DrivesOfOneRestAreTheRunsTheirOwnRigsMakeBitForBit) {
  // the load and settle phases do not depend on the drive: a towed rig's rest, driven at 30 %
  // slip, is the run a rig at 30 % slip makes from its own preparation and rest, to the last bit
  // (a short window at the tiny level: 0.3 m of travel)
  const auto params = [](const std::string& drive) {
    return SingleWheelParams::Read(YamlReader::LoadWithOverrides(
        SceneFile(), {"fidelity=tiny", "threads=1", "wheel.drive=" + drive, "wheel.slip=0.3", "carriage.window=[0.8, 1.1]"}));
  };
  SingleWheelRig own(params("slip"));
  RunSoilRig(own);
  SingleWheelRig towed(params("towed"));
  while (!towed.driving()) towed.Step();
  // (not rested yet, or driven already: refused, naming the file)
  SingleWheelRig early(params("slip"));
  early.Step();
  EXPECT_THROW(SingleWheelRig(early, SingleWheelParams::Drive::kSlip, 0.3, 0.0), ConfigError);
  EXPECT_THROW(SingleWheelRig(towed, SingleWheelParams::Drive::kSlip, 1.0, 0.0), ConfigError);
  EXPECT_THROW(SingleWheelRig(towed, SingleWheelParams::Drive::kTorque, 0.0, 2e5), ConfigError);
  SingleWheelRig shared(towed, SingleWheelParams::Drive::kSlip, 0.3, 0.0);
  RunSoilRig(shared);
  EXPECT_THROW(SingleWheelRig(shared, SingleWheelParams::Drive::kSlip, 0.3, 0.0), ConfigError);
  ASSERT_TRUE(own.done() && shared.done());
  ASSERT_TRUE(own.error().empty() && shared.error().empty()) << own.error() << shared.error();
  EXPECT_EQ(shared.params().drive, SingleWheelParams::Drive::kSlip);
  ASSERT_GT(own.samples().size(), 10u);
  ASSERT_EQ(own.samples().size(), shared.samples().size());
  for (size_t k = 0; k < own.samples().size(); ++k) {
    const WheelSample &a = own.samples()[k], &b = shared.samples()[k];
    EXPECT_TRUE(a.drawbar_pull == b.drawbar_pull && a.torque == b.torque && a.sinkage == b.sinkage &&
                a.omega == b.omega && a.vertical_force == b.vertical_force)
        << "sample " << k << ": DP " << a.drawbar_pull << " / " << b.drawbar_pull;
  }
  EXPECT_EQ(own.rest_vertical_force(), shared.rest_vertical_force());
  const auto pa = own.dem().positions(), pb = shared.dem().positions();
  ASSERT_EQ(pa.size(), pb.size());
  long differ = 0;
  for (size_t i = 0; i < pa.size(); ++i) differ += (pa[i].array() != pb[i].array()).any();
  EXPECT_EQ(differ, 0);
  // the drive is the commanded one: the wheel turns at v / (r (1 - 0.3)) once the carriage is at speed
  const SingleWheelParams p = params("slip");
  EXPECT_NEAR(shared.samples().back().omega, p.speed / (p.tire.radius * 0.7), 1e-9 * p.speed / p.tire.radius);
}

}  // namespace
}  // namespace dem_mobility::core
