#include "dem_mobility/core/terrain/road_terrain.h"
#include "dem_mobility/core/common/state_archive.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/geometry/terrain_mesh.h"
#include "dem_mobility/core/multibody/contact.h"

namespace dem_mobility::core {
namespace {

struct RoadParams {
  TerrainDescription description;
  double length = 0.0, width = 0.0, cell = 0.0, start = 0.0;
  ContactParams contact;
};

RoadParams ReadRoad(const YamlReader& y, const TerrainVehicle& vehicle) {
  RoadParams p;
  p.description = DescribeRoadTerrain(y);
  p.length = y.DoubleIn("length", 1.0, 1e5);
  p.width = y.DoubleIn("width", 3.0, 1000.0);
  p.cell = y.DoubleIn("cell", 0.05, 100.0);
  p.start = y.DoubleIn("start_x", -1e5, 1e5);
  const double cells = std::ceil(p.length / p.cell) * std::ceil(p.width / p.cell);
  if (cells > 1e7)
    y.Fail("cell", detail::Concat("a ", p.length, " x ", p.width, " m road in cells of ", p.cell, " m has ", cells,
                                  " cells, more than 1e7: a larger cell or a shorter road"));
  const YamlReader c = y.Child("contact");
  p.contact = ContactParams::Read(c);
  c.Finish();
  y.Finish();
  DM_THROW_UNLESS(vehicle.wheels == kWheels, y.file(), ": rigid_road carries ", kWheels, " wheels, not ",
                  vehicle.wheels);
  return p;
}

class RoadTerrain final : public TerrainModel {
 public:
  RoadTerrain(const YamlReader& y, const TerrainVehicle& vehicle) : tire_(vehicle.tire) {
    const RoadParams p = ReadRoad(y, vehicle);
    const ContactParams& params = p.contact;
    description_ = p.description;
    half_width_ = 0.5 * p.width;
    file_ = y.file();
    mesh_ = std::make_unique<TerrainMesh>(MakeFlatRoad(p.start, p.length, p.width, p.cell), p.cell, 0.05);
    bodies_.resize(kWheels);
    for (int i = 0; i < kWheels; ++i) {
      bodies_[i].name = std::string("wheel_") + kWheelNames[i];
      TireContact& tc = tires_[i];
      tc.name = std::string("tire_") + kWheelNames[i];
      tc.body = i;
      tc.tire = &tire_;
      tc.params = params;
      tc.terrain = mesh_.get();
    }
    const int n = tires_[0].SimultaneousVertices();
    stiffness_ = n * std::max(params.k_n, params.k_t);
    damping_ = n * params.c_n;
    wrenches_.resize(kWheels);
  }

  const TerrainDescription& description() const override { return description_; }
  const TriMesh& Surface() const override { return mesh_->mesh(); }

  void Synchronize(long step, double /*t*/, const std::vector<WheelState>& states) override {
    DM_THROW_UNLESS(states.size() == kWheels, "rigid_road: expected ", kWheels, " wheel states, got ", states.size());
    for (int i = 0; i < kWheels; ++i) {
      const WheelState& s = states[i];
      // a wheel past the road's edge is off the road: the run cannot go on as a run on this road
      if (std::abs(s.position.y()) > half_width_)
        throw SimulationError(detail::Concat("rigid_road (", file_, "): wheel ", kWheelNames[i], " is at y = ",
                                             s.position.y(), " m, off the road (", 2.0 * half_width_,
                                             " m wide, `width`): the vehicle veered off its course"));
      RigidBody& b = bodies_[i];
      b.x = s.position;
      b.R = s.orientation.toRotationMatrix();
      b.v = s.velocity;
      b.w_world = s.angular_velocity;
      b.force.setZero();
      b.torque.setZero();
      tires_[i].Apply(bodies_, step);
      WheelWrench& w = wrenches_[i];
      w.force = b.force;
      w.moment = b.torque;
      w.sinkage = tires_[i].last.max_depth;
      w.contacts = tires_[i].last.num_contacts;
      w.normal_force = tires_[i].last.normal_force;
      w.stiffness = stiffness_;
      w.damping = damping_;
    }
  }
  void GetWrenches(std::vector<WheelWrench>* wrenches) const override { *wrenches = wrenches_; }
  void Advance(double /*dt*/) override {}
  void SaveState(StateWriter& out) const override { const_cast<RoadTerrain*>(this)->Io(out); }
  void LoadState(StateReader& in) override { Io(in); }

 private:
  /// The exchanged wheel states, the tires' contact anchors and the wrenches.
  template <class Ar>
  void Io(Ar& ar) {
    ar.Tag("rigid_road");
    for (RigidBody& b : bodies_) b.Io(ar);
    for (TireContact& t : tires_) {
      ar(t.last, t.history);  // (one anchor per tire vertex, or none before the first contact)
    }
    ar(wrenches_);
    if constexpr (Ar::kLoading)
      if (wrenches_.size() != kWheels) ar.Fail("the road's wrenches do not match the wheels");
  }

  TerrainDescription description_;
  TireGeometry tire_;
  std::unique_ptr<TerrainMesh> mesh_;
  Bodies bodies_;  ///< one stand-in body per wheel, holding the exchanged state
  TireContact tires_[kWheels];
  std::vector<WheelWrench> wrenches_;
  double stiffness_ = 0.0, damping_ = 0.0, half_width_ = 0.0;
  std::string file_;
};

}  // namespace

TerrainDescription DescribeRoadTerrain(const YamlReader& y) {
  TerrainDescription d;
  d.file = y.file();
  d.model = y.String("model");
  d.cone_index = y.DoubleIn("cone_index_psi", 1.0, 1000.0);
  return d;
}

void CheckRoadTerrain(const YamlReader& y, const TerrainVehicle& vehicle) { ReadRoad(y, vehicle); }

std::unique_ptr<TerrainModel> MakeRoadTerrain(const YamlReader& y, const TerrainVehicle& vehicle) {
  return std::make_unique<RoadTerrain>(y, vehicle);
}

}  // namespace dem_mobility::core
