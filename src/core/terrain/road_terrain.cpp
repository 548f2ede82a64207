// The rigid polygonal road as a terrain model: the tire vertices of each wheel (the paper's master
// surface) against the road's triangles (the slave surface), with the asperity friction model.
#include <cmath>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/multibody/contact.h"
#include "dem_mobility/core/terrain/terrain_model.h"
#include "dem_mobility/core/vehicle/vehicle.h"

namespace dem_mobility {
namespace {

class RoadTerrain final : public TerrainModel {
 public:
  RoadTerrain(const YamlReader& y, const TireGeometry& tire) : tire_(tire) {
    const double length = y.Positive("length");
    const double width = y.DoubleIn("width", 3.0, 1000.0);
    const double cell = y.Positive("cell");
    const double start = y.Double("start_x");
    const YamlReader c = y.Child("contact");
    const ContactParams params = ContactParams::Read(c);
    c.Finish();
    y.Finish();
    mesh_ = std::make_unique<TerrainMesh>(MakeFlatRoad(start, length, width, cell), cell, 0.05);
    bodies_.resize(4);
    for (int i = 0; i < 4; ++i) {
      bodies_[i].name = std::string("wheel_") + "0123"[i];
      TireContact& tc = tires_[i];
      tc.name = "tire " + std::to_string(i);
      tc.body = i;
      tc.tire = &tire_;
      tc.params = params;
      tc.terrain = mesh_.get();
    }
    const int n = tires_[0].SimultaneousVertices();
    stiffness_ = n * std::max(params.k_n, params.k_t);
    damping_ = n * params.c_n;
  }

  std::string kind() const override { return "rigid_road"; }
  const TriMesh& Surface() const override { return mesh_->mesh(); }

  void Compute(long step, double /*t*/, const std::vector<WheelState>& states,
               std::vector<WheelWrench>* wrenches) override {
    DM_THROW_UNLESS(states.size() == 4, "rigid_road: expected 4 wheel states, got ", states.size());
    wrenches->resize(4);
    for (int i = 0; i < 4; ++i) {
      const WheelState& s = states[i];
      RigidBody& b = bodies_[i];
      b.x = s.position;
      b.R = s.orientation.toRotationMatrix();
      b.v = s.velocity;
      b.w_world = s.angular_velocity;
      b.force.setZero();
      b.torque.setZero();
      tires_[i].Apply(bodies_, step);
      WheelWrench& w = (*wrenches)[i];
      w.force = b.force;
      w.moment = b.torque;
      w.sinkage = tires_[i].last.max_depth;
      w.contacts = tires_[i].last.num_contacts;
      w.normal_force = tires_[i].last.normal_force;
      w.stiffness = stiffness_;
      w.damping = damping_;
    }
  }

 private:
  TireGeometry tire_;
  std::unique_ptr<TerrainMesh> mesh_;
  Bodies bodies_;  ///< one stand-in body per wheel, holding the exchanged state
  TireContact tires_[4];
  double stiffness_ = 0.0, damping_ = 0.0;
};

}  // namespace

std::unique_ptr<TerrainModel> LoadTerrainModel(const std::string& terrain_file, const std::string& vehicle_file) {
  const YamlReader y = YamlReader::Load(terrain_file);
  const std::string model = y.String("model");
  if (model == "rigid_road") return std::make_unique<RoadTerrain>(y, LoadTireGeometry(vehicle_file));
  y.Fail("model", "unknown terrain model '" + model + "' (known: rigid_road)");
  return nullptr;
}

}  // namespace dem_mobility
