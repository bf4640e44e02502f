#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Tangential spring with history and a Coulomb cap (LIGGGHTS `tangential history`, paper eq. 1).
// shear[0..2] is the spring displacement of i relative to j (m).
struct TangentialHistory {
  static void apply(const ContactInput& c, const PairParams& p, double gamma_t, double dt,
                    double* shear, ContactResult& result) {
    const Vec3& n = c.n;
    // Relative velocity of the contact points, tangential part.
    const Vec3 vn = dot(c.v_rel, n) * n;
    const Vec3 vt = c.v_rel - vn + cross(n, c.cri * c.omega_i + c.crj * c.omega_j);
    Vec3 s{shear[0] + vt.x * dt, shear[1] + vt.y * dt, shear[2] + vt.z * dt};
    s -= dot(s, n) * n;  // keep the spring in the current tangent plane
    const double kt = result.kt;
    Vec3 ft = -kt * s;
    const double ft_elastic = kt * norm(s);
    const double ft_max = p.mu_s * std::fabs(result.fn);
    if (ft_elastic > ft_max) {
      if (ft_elastic > 0.0) {
        ft *= ft_max / ft_elastic;
        s = -(1.0 / kt) * ft;
      } else {
        ft = Vec3{};
      }
    } else {
      ft -= gamma_t * vt;
    }
    shear[0] = s.x;
    shear[1] = s.y;
    shear[2] = s.z;
    result.force = result.fn * n + ft;
    const Vec3 arm = cross(n, ft);
    result.torque_i = -c.cri * arm;
    result.torque_j = -c.crj * arm;
  }
};

}  // namespace dem
