#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Elastic-plastic spring-dashpot rolling resistance, variant 2 (LIGGGHTS `rolling_friction
// epsd2`, paper eq. 2): torque spring of stiffness kt R*^2 driven by the relative rolling
// velocity, capped at mu_r R* |Fn| (Fn: ContactResult::fn_limit), without a viscous term.
struct RollingEpsd2 {
  static void apply(const ContactInput& c, const PairParams& p, const ContactStep& step,
                    double* history, ContactResult& result) {
    double* torque = history + kRollingHistory;
    const Vec3& n = c.n;
    // Relative angular velocity; against a wall LIGGGHTS scales the particle's by the ratio
    // of the contact radius to the centre-wall distance, (R - dn/2) / (R - dn).
    Vec3 w_rel = c.wall ? (c.cri / c.dist) * c.omega_i : c.omega_i - c.omega_j;
    w_rel -= dot(w_rel, n) * n;  // twisting is not resisted
    const double kr = result.kt * c.r_eff * c.r_eff;
    Vec3 m{torque[0], torque[1], torque[2]};
    // The increment enters the torque at the set-up of a run as well, but is stored only by
    // the steps that advance the history.
    m += (kr * step.dt) * w_rel;
    const double m_mag = norm(m);
    const double m_max = p.mu_r * c.r_eff * std::fabs(result.fn_limit);
    if (m_mag > m_max && m_mag > 0.0) m *= m_max / m_mag;
    if (step.update_history) {
      torque[0] = m.x;
      torque[1] = m.y;
      torque[2] = m.z;
    }
    result.torque_i -= m;
    result.torque_j += m;
  }
};

}  // namespace dem
