#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Elastic-plastic spring-dashpot rolling resistance, variant 2 (LIGGGHTS `rolling_friction
// epsd2`, paper eq. 2): torque spring of stiffness kt R*^2 driven by the relative rolling
// velocity, capped at mu_r R* |Fn| (Fn: ContactResult::fn_limit), without a viscous term.
struct RollingEpsd2 {
  template <class R>
  DEM_INLINE static void apply(const ContactInputT<R>& c, const PairParamsT<R>& p,
                               const ContactStep& step, R* history, ContactResultT<R>& result) {
    using V = Vec3Of<R>;
    R* torque = history + kRollingHistory;
    const V& n = c.n;
    // Relative angular velocity; against a wall LIGGGHTS scales the particle's by the ratio
    // of the contact radius to the centre-wall distance, (R - dn/2) / (R - dn).
    V w_rel = c.wall ? (c.cri / c.dist) * c.omega_i : c.omega_i - c.omega_j;
    w_rel -= dot(w_rel, n) * n;  // twisting is not resisted
    const R kr = result.kt * c.r_eff * c.r_eff;
    V m{torque[0], torque[1], torque[2]};
    // The increment enters the torque at the set-up of a run as well, but is stored only by
    // the steps that advance the history.
    m += (kr * step.dt) * w_rel;
    const R m_mag = norm(m);
    const R m_max = p.mu_r * c.r_eff * lane_abs(result.fn_limit);
    const auto capped = m_mag > m_max && m_mag > 0.0;
    if (any(capped)) m = select(capped, m * (m_max / m_mag), m);
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
