// Penalty contact of points on rigid bodies against a terrain surface (paper section 2.2, eq. 8-14)
// with the asperity friction model: a velocity-dependent Coulomb element in parallel with a
// variable-anchor spring, so a body at rest on a slope below the friction limit stays put.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dem_mobility/core/multibody/elements.h"
#include "dem_mobility/core/geometry/terrain_mesh.h"
#include "dem_mobility/core/geometry/tire_geometry.h"

namespace dem_mobility::core {

class YamlReader;

struct ContactParams {
  double k_n = 0.0;          ///< normal penalty stiffness per contact point [N/m]
  double c_n = 0.0;          ///< normal damping [N s/m]
  double s_n = 0.0;          ///< separation factor of the damping (0..1, eq. 12b)
  double mu = 0.0;           ///< friction coefficient
  double k_t = 0.0;          ///< anchor spring stiffness [N/m]
  double c_t_anchor = 0.0;   ///< damping in parallel with the anchor spring [N s/m]
  double v_slip = 0.0;       ///< velocity at which the Coulomb element saturates [m/s]
  double c_visc = 0.0;       ///< tangential viscosity c_t of eq. 14 [N s/m]
  double c_rr = 0.0;         ///< rolling resistance coefficient (tires only)
  /// Reads and checks the keys of a contact block (k_n, c_n, s_n, mu, k_t, ...).
  static ContactParams Read(const YamlReader& y);
};

/// History of one contact point: where its anchor sits on the surface, and whether it was in
/// contact at the previous step (a point out of contact loses its anchor).
struct ContactHistory {
  using StateBulk = void;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
  long last_step = -2;
};

/// Normal and tangential force of one contact point. `r` is the point's world offset from the
/// body COM. Returns the force on the body (world) and updates the history.
/// depth > 0, n the outward surface normal, v the point's velocity relative to the surface.
Eigen::Vector3d ContactForce(const ContactParams& p, const Eigen::Vector3d& point,
                             const Eigen::Vector3d& n, double depth, const Eigen::Vector3d& v,
                             long step, ContactHistory* h, double* normal_force);

/// Summary of a contact set's forces in the last evaluation.
struct ContactSummary {
  using StateBulk = void;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< on the body, world
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  ///< on the body about its COM, world
  double normal_force = 0.0;                         ///< sum of normal force magnitudes
  double max_depth = 0.0;
  int num_contacts = 0;
};

/// A set of contact points fixed on a body (e.g. the corners of a box), all tested every step.
struct PointSetContact {
  std::string name;
  int body = 0;
  std::vector<Eigen::Vector3d> points;   ///< body coordinates relative to the COM
  ContactParams params;
  const TerrainMesh* terrain = nullptr;
  std::vector<ContactHistory> history;
  ContactSummary last;
  long applied_step = -1;  ///< step of the last Apply
  void Apply(Bodies& bodies, long step);
  double PotentialEnergy(const Bodies& bodies) const;
  StiffnessInfo Stiffness(const Bodies& bodies) const;
};

/// Contact of a rigid tire (vertices of its mesh as contact points, the paper's master surface)
/// against the terrain (the slave surface). Also applies the rolling-resistance moment.
struct TireContact {
  std::string name;
  int body = 0;
  const TireGeometry* tire = nullptr;
  ContactParams params;
  const TerrainMesh* terrain = nullptr;
  std::vector<ContactHistory> history;  ///< one per tire vertex
  ContactSummary last;
  void Apply(Bodies& bodies, long step);
  /// How many tire vertices can touch the terrain at once (the columns within its max_depth).
  int SimultaneousVertices() const;
};

}  // namespace dem_mobility::core
