#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Elastic-plastic spring-dashpot rolling resistance, variant 2 (LIGGGHTS `rolling_friction
// epsd2`, paper eq. 2): torque spring of stiffness kt R*^2 driven by the relative rolling
// velocity, capped at mu_r R* |Fn|, without a viscous term. torque[0..2] is the spring torque.
struct RollingEpsd2 {
  static void apply(const ContactInput& c, const PairParams& p, double dt, double* torque,
                    ContactResult& result) {
    const Vec3& n = c.n;
    Vec3 w_rel = c.omega_i - c.omega_j;
    w_rel -= dot(w_rel, n) * n;  // twisting is not resisted
    const double kr = result.kt * c.r_eff * c.r_eff;
    Vec3 m{torque[0] + kr * w_rel.x * dt, torque[1] + kr * w_rel.y * dt,
           torque[2] + kr * w_rel.z * dt};
    const double m_mag = norm(m);
    const double m_max = p.mu_r * c.r_eff * std::fabs(result.fn);
    if (m_mag > m_max && m_mag > 0.0) m *= m_max / m_mag;
    torque[0] = m.x;
    torque[1] = m.y;
    torque[2] = m.z;
    result.torque_i -= m;
    result.torque_j += m;
  }
};

}  // namespace dem
