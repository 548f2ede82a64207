// The asperity friction element (paper eq. 13-14), shared by the soil particles and the tire-road
// contact: a Coulomb element mu F_rep, linear in the sliding velocity below the slip speed, in
// parallel with a variable-anchor spring (and optionally a dashpot beside it), the two capped
// together at mu F_rep; when the cap binds, the anchor slides so that the spring carries what the
// Coulomb element does not. A viscous term c_visc acts outside the cap.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace dem_mobility::core {

struct AsperityFriction {
  double mu = 0.0;        ///< friction coefficient
  double k_t = 0.0;       ///< anchor spring stiffness [N/m]
  double inv_k_t = 0.0;   ///< 1 / k_t (0 without a spring)
  double v_slip = 0.0;    ///< sliding speed at which the Coulomb element saturates [m/s]
  double c_anchor = 0.0;  ///< dashpot beside the spring, inside the cap [N s/m] (with kAnchorDamping)
  double c_visc = 0.0;    ///< viscosity outside the cap [N s/m]

  AsperityFriction() = default;
  AsperityFriction(double mu_, double k_t_, double v_slip_, double c_anchor_, double c_visc_)
      : mu(mu_), k_t(k_t_), inv_k_t(k_t_ > 0.0 ? 1.0 / k_t_ : 0.0), v_slip(v_slip_), c_anchor(c_anchor_),
        c_visc(c_visc_) {}

  /// The Coulomb element's damping coefficient (negative: it opposes vt) at sliding speed `speed`.
  /// Below the slip speed the element is a dashpot of mu f_rep / v_slip, which an explicit step
  /// resolves only for dt < m v_slip / (mu f_rep) (3e-5 s for a 0.1 m soil particle under 300 N);
  /// beyond that it reverses the sliding every step, and each reversal resets the anchor, so the
  /// spring never holds a sticking contact. `step_per_mass` > 0 (the step over the mass the
  /// dashpot acts on) integrates it backward (implicit Euler): c / (1 + c dt / m), which never
  /// reverses the sliding in one step and tends to c as dt -> 0. 0 keeps it explicit.
  [[gnu::always_inline]] static double CoulombDamping(double mu, double f_rep, double v_slip, double speed,
                                                      double step_per_mass) {
    const double c = -mu * f_rep / std::max(v_slip, speed);
    return c / (1.0 - c * step_per_mass);
  }

  /// The tangential force on this body for a sliding velocity `vt` (in the tangent plane),
  /// repulsive normal force `f_rep` and spring elongation `*s` (this body's contact point less the
  /// anchor, in the tangent plane); on slip `*s` is set to where the anchor slid (and `*slipped`,
  /// if given, to true). `step_per_mass`: see CoulombDamping.
  template <bool kAnchorDamping = false>
  [[gnu::always_inline]] Eigen::Vector3d Force(const Eigen::Vector3d& vt, double f_rep, Eigen::Vector3d* s,
                                               bool* slipped = nullptr, double step_per_mass = 0.0) const {
    const double c = CoulombDamping(mu, f_rep, v_slip, vt.norm(), step_per_mass);
    const Eigen::Vector3d f_c = c * vt;
    Eigen::Vector3d f_t = -k_t * *s + f_c;
    if constexpr (kAnchorDamping) f_t -= c_anchor * vt;
    const double limit = mu * std::max(0.0, f_rep);
    const double ft2 = f_t.squaredNorm();
    if (ft2 > limit * limit) {
      f_t = ft2 > 0.0 ? Eigen::Vector3d(f_t * (limit / std::sqrt(ft2))) : Eigen::Vector3d::Zero();
      *s = -(f_t - f_c) * inv_k_t;
      if (slipped) *slipped = true;
    }
    return f_t - c_visc * vt;
  }
};

}  // namespace dem_mobility::core
