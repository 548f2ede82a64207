// The cohesive soil particle law of the paper's section 2.3: normal force = adhesion + repulsion +
// damping (eq. 15, 12b; fig. 7), a per-particle plastic deformation that grows with the particle's
// largest compressive force (fig. 8), is kept after unloading and relaxes at V_relax while that
// releases energy, i.e. while the particle is pulled apart (eq. 16), a maximum adhesion that grows with the
// plastic strain (fig. 10, scaled by the cohesion factor f), and the asperity friction of eq. 13-14
// (a Coulomb element in parallel with a variable-anchor spring, capped at mu F_repulsion).
//
// Sign convention: a penetration d > 0 means overlap; a normal force > 0 pushes the particles apart.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "dem_mobility/core/common/asperity_friction.h"
#include "dem_mobility/core/common/table.h"

namespace dem_mobility::core {

class YamlReader;

struct SoilParams {
  std::string file;
  double diameter = 0.0;            ///< unstressed diameter d [m]
  double density = 0.0;             ///< [kg/m^3]
  double stiffness_stress = 0.0;    ///< repulsion stress per penetration strain [N/m^2]
  double damping_area = 0.0;        ///< damping per unit area [N s/m^3]
  double separation_factor = 0.0;   ///< s_n
  double adhesion_depth = 0.0;      ///< d0 / d
  double adhesion_peak = 0.0;       ///< penetration / d at the full adhesion
  double friction = 0.0;            ///< mu
  double tangential_stiffness_ratio = 0.0;
  double slip_velocity = 0.0;       ///< [m/s]
  double viscosity = 0.0;           ///< c_t [N s/m]
  double cohesion_factor = 1.0;     ///< f
  double relax_speed = 0.0;         ///< V_relax [m/s]
  bool plasticity = true, cohesion = true;
  Table1D plastic_strain_vs_stress;           ///< fig. 8
  Table1D adhesion_stress_vs_plastic_strain;  ///< fig. 10 (nominal, f = 1)

  /// Reads and checks a soil file (config/soils/*.yaml); ConfigError names file and key.
  static SoilParams Read(const YamlReader& y);

  // derived
  double Area() const { return 0.25 * M_PI * diameter * diameter; }  ///< pi d^2 / 4: the area stresses refer to
  double Mass() const;          ///< rho pi d^3 / 6
  double NormalStiffness() const { return stiffness_stress * Area() / diameter; }  ///< k_n [N/m]
  double NormalDamping() const { return damping_area * Area(); }                    ///< c_n [N s/m]
  double TangentialStiffness() const { return tangential_stiffness_ratio * NormalStiffness(); }
};

/// The parts of the normal force of one contact (eq. 15), each signed (> 0 repulsive).
struct SoilNormalForce {
  double adhesion = 0.0;   ///< <= 0
  double repulsion = 0.0;  ///< >= 0
  double damping = 0.0;
  double Total() const { return adhesion + repulsion + damping; }
};

/// Tangential (history) state of a contact: the elongation of the anchor spring.
struct TangentialHistory {
  using StateBulk = void;
  Eigen::Vector3d spring = Eigen::Vector3d::Zero();
};

/// The contact law of a pair (or a particle and a wall) with its constants worked out once: the
/// solver's inner loop, and what the tests check against the formulas.
struct SoilContactLaw {
  /// The sticking contacts the Coulomb element's implicit step shares a particle's mass among:
  /// about four, the coordination of a frictional packing at rest. Measured on the 0.1 m cone at
  /// f 5 (1.2e-4 / 3e-5 s): a pair's half mass over 1, 4 and 12 contacts reads 242/254, 272/264
  /// and 284/264 psi (the explicit dashpot 100/206, 295 at 3.75e-6 s); over 12, a poured bed at
  /// f 3 still moves at 1.8e-3 m/s after 1 s (docs/soil-model.md, "Tangential force").
  static constexpr double kDampedNeighbours = 4.0;
  double k_n, c_n, d0, dp, inv_dp, inv_d0_dp, s_n;
  AsperityFriction friction;  ///< eq. 13-14, the viscosity c_t outside the cap
  bool cohesion;
  /// 1 / the mass the Coulomb element's dashpot acts on in one contact: half a particle's mass
  /// (a pair's reduced mass) shared among kDampedNeighbours contacts (AsperityFriction::CoulombDamping).
  double inv_damped_mass;
  explicit SoilContactLaw(const SoilParams& p)
      : k_n(p.NormalStiffness()),
        c_n(p.NormalDamping()),
        d0(p.adhesion_depth * p.diameter),
        dp(p.adhesion_peak * p.diameter),
        inv_dp(dp > 0.0 ? 1.0 / dp : 0.0),
        inv_d0_dp(d0 > dp ? 1.0 / (d0 - dp) : 0.0),
        s_n(p.separation_factor),
        friction(p.friction, p.TangentialStiffness(), p.slip_velocity, 0.0, p.viscosity),
        cohesion(p.cohesion),
        inv_damped_mass(p.Mass() > 0.0 ? 2.0 * kDampedNeighbours / p.Mass() : 0.0) {}

  /// Normal force of a contact with effective penetration `d` (the geometric overlap less the
  /// plastic deformations of the two particles), penetration rate `d_dot` (> 0 approaching) and
  /// maximum adhesion `f_adh_max` [N] (fig. 7): for 0 < d < d0 attractive, rising to -f_adh_max at
  /// the peak penetration and back to 0 at d0; beyond d0 repulsive, k_n (d - d0). Damping c_n d_dot,
  /// times s_n while separating. No force for d <= 0.
  // Branch-free in the penetration: in a packed bed the penetrations sit about d0, where a branch
  // on the adhesion/repulsion boundary is mispredicted half the time.
  [[gnu::always_inline]] SoilNormalForce Normal(double d, double d_dot, double f_adh_max) const {
    SoilNormalForce f;
    if (!(d > 0.0)) return f;
    // the adhesion triangle: rising as d / dp up to the peak, falling as (d0 - d) / (d0 - dp) to d0
    if (cohesion) f.adhesion = -std::max(0.0, f_adh_max) * std::max(0.0, std::min(d * inv_dp, (d0 - d) * inv_d0_dp));
    f.repulsion = k_n * std::max(0.0, d - d0);
    f.damping = c_n * (std::max(d_dot, 0.0) + s_n * std::min(d_dot, 0.0));
    return f;
  }

  /// Tangential force (eq. 13-14) of a contact with unit normal `n` (from the other body toward
  /// this one), relative tangential velocity `vt` (this body's contact point relative to the
  /// other's) and repulsive force `f_rep`, on this body: the anchor spring is kept in the current
  /// tangent plane (projected, as LAMMPS' history springs are; the length lost is second order in
  /// the turn per step) and stretched by vt dt; the anchor slides when the force exceeds mu f_rep.
  /// The Coulomb element's dashpot is stepped implicitly (AsperityFriction::CoulombDamping).
  [[gnu::always_inline]] Eigen::Vector3d Tangential(const Eigen::Vector3d& n, const Eigen::Vector3d& vt, double f_rep,
                                                    double dt, TangentialHistory* h) const {
    Eigen::Vector3d s = h->spring;
    s -= s.dot(n) * n;
    s += vt * dt;
    const Eigen::Vector3d f_t = friction.Force(vt, f_rep, &s, nullptr, dt * inv_damped_mass);
    h->spring = s;
    return f_t;
  }
};

/// Maximum adhesion force of a particle with plastic deformation `delta_p` [m]: f x fig. 10 at the
/// plastic strain delta_p / d, times the area. 0 when cohesion is off.
double MaxAdhesionForce(const SoilParams& p, double delta_p);

/// The adhesion triangle's integral from 0 to the effective penetration `d` at unit maximum
/// adhesion [m]: how much a contact's energy falls per newton of maximum adhesion (its adhesive
/// energy is -f_adh_max times this). 0 for d <= 0, d0 / 2 beyond d0. `inv_dp`, `inv_d0_dp`: as
/// SoilContactLaw's (no division on a vector lane). Branch-free in `d`, both arms computed.
[[gnu::always_inline]] inline double AdhesionReach(double d0, double dp, double inv_dp, double inv_d0_dp, double d) {
  const double a = std::max(0.0, std::min(d, d0)), past = a - dp;
  const double rising = 0.5 * a * a * inv_dp;
  const double falling = (0.5 * dp + past) - 0.5 * past * past * inv_d0_dp;
  return a <= dp ? rising : falling;
}

/// What a particle's contacts tell its plastic update (summed over them at the last force
/// evaluation): its largest repulsive force, the sum of their elastic normal forces (adhesion +
/// repulsion, > 0 pushing it out), the sum of AdhesionReach over the contacts whose maximum
/// adhesion is the particle's own (a pair takes the smaller of its two, a wall its factor times
/// the particle's; such a wall contact counts its factor times the reach), and their number (a
/// wall adhering more than a particle counts its factor).
struct PlasticDrive {
  double max_repulsion = 0.0, normal_sum = 0.0, adhesion_reach = 0.0, contacts = 0.0;
};

/// One step of a particle's plastic deformation `delta_p` (eq. 16 and fig. 8, as read in
/// docs/soil-model.md, "Reading of eq. 16"): it grows to fig. 8 at the stress of its largest
/// repulsive force (never shrinks from loading); otherwise it relaxes by V_relax dt, floored at
/// zero and at fig. 8's value for the present load, when that relaxation releases energy: when,
/// at the particle's present contacts, the deformation given back (each contact's penetration
/// deeper by the step) and the adhesion lost with it (f x fig. 10 at the lower strain) together
/// lower the contacts' stored energy, which is when the particle is pulled apart ("reduction of
/// soil cohesive strength and soil bulk density due to tension"). Plastic relaxation is then
/// dissipative, as plastic flow is: it never pushes a bed at rest into motion. `adhesion_max` is
/// the particle's present MaxAdhesionForce(p, delta_p). Unchanged when plasticity is off.
inline double UpdatePlasticDeformation(const SoilParams& p, double delta_p, double adhesion_max,
                                       const PlasticDrive& drive, double dt) {
  // (inline: the DEM step calls it for every particle)
  if (!p.plasticity) return delta_p;
  const double target = p.plastic_strain_vs_stress(drive.max_repulsion / p.Area()) * p.diameter;
  if (target > delta_p) return target;  // loading beyond the history: the deformation grows (fig. 8)
  // Floored at what fig. 8 gives for the present load: only the part left from earlier, higher
  // loads relaxes, so the next step does not grow it back by V_relax dt (a force jump of
  // k_n V_relax dt on a lightly loaded particle).
  const double relaxed = std::max(target, delta_p - p.relax_speed * dt);
  if (!(relaxed < delta_p)) return delta_p;
  // The change of the contacts' energy at fixed positions if it relaxes: to first order each
  // contact's penetration deeper by the step s (its elastic normal force times s) and its adhesive
  // energy less by the adhesion lost da (its reach times da); plus, per contact, a bound of the
  // second-order rest: the force's largest slope over the step (k_n, or the adhesion triangle's
  // falling side, a / (d0 - dp)) times s^2 / 2, and da s (the triangle's slope is at most 1 per
  // unit a), both doubled for a partner relaxing in the same step (its s deepens the contact too).
  // A free particle moves no energy and relaxes.
  const double s = delta_p - relaxed, da = adhesion_max - MaxAdhesionForce(p, relaxed);
  const double falling = (p.adhesion_depth - p.adhesion_peak) * p.diameter;
  const double slope = std::max(p.NormalStiffness(), falling > 0.0 ? adhesion_max / falling : 0.0);
  const double first = s * drive.normal_sum + da * drive.adhesion_reach;
  const double second = drive.contacts * (slope * s * s + 2.0 * da * s);
  return first + second <= 0.0 ? relaxed : delta_p;
}

}  // namespace dem_mobility::core
