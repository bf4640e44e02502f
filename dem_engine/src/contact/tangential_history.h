#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Tangential spring with history and a Coulomb cap (LIGGGHTS `tangential history`, paper eq. 1).
// The spring is the displacement of i relative to j at the contact point (m), kept in the
// tangent plane. Writes the total force (normal + tangential) and the torques of the
// tangential force.
struct TangentialHistory {
  static void apply(const ContactInput& c, const PairParams& p, const ContactStep& step,
                    double* history, ContactResult& result) {
    double* shear = history + kTangentialHistory;
    const Vec3& n = c.n;
    // Relative velocity of the contact points, tangential part.
    const Vec3 vn = dot(c.v_rel, n) * n;
    const Vec3 vt = c.v_rel - vn + cross(n, c.cri * c.omega_i + c.crj * c.omega_j);
    Vec3 s{shear[0], shear[1], shear[2]};
    if (step.update_history) {
      s += step.dt * vt;
      s -= dot(s, n) * n;  // keep the spring in the current tangent plane
    }
    const double kt = result.kt;
    Vec3 ft = -kt * s;
    const double ft_elastic = kt * norm(s);
    const double ft_max = p.mu_s * std::fabs(result.fn_limit);
    if (ft_elastic > ft_max) {
      if (ft_elastic > 0.0) {
        ft *= ft_max / ft_elastic;
        s = -(1.0 / kt) * ft;
      } else {
        ft = Vec3{};
      }
    } else {
      ft -= result.gamma_t * vt;
    }
    if (step.update_history) {
      shear[0] = s.x;
      shear[1] = s.y;
      shear[2] = s.z;
    }
    result.force = result.fn * n + ft;
    const Vec3 arm = cross(n, ft);
    result.torque_i = -c.cri * arm;
    result.torque_j = -c.crj * arm;
  }
};

}  // namespace dem
