#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Tangential spring with history and a Coulomb cap (LIGGGHTS `tangential history`, paper eq. 1).
// The spring is the displacement of i relative to j at the contact point (m), kept in the
// tangent plane. Writes the total force (normal + tangential) and the torques of the
// tangential force.
struct TangentialHistory {
  template <class R>
  DEM_INLINE static void apply(const ContactInputT<R>& c, const PairParamsT<R>& p,
                               const ContactStep& step, R* history, ContactResultT<R>& result) {
    using V = Vec3Of<R>;
    R* shear = history + kTangentialHistory;
    const V& n = c.n;
    // Relative velocity of the contact points, tangential part.
    const V vn = dot(c.v_rel, n) * n;
    const V vt = c.v_rel - vn + cross(n, c.cri * c.omega_i + c.crj * c.omega_j);
    V s{shear[0], shear[1], shear[2]};
    if (step.update_history) {
      s += step.dt * vt;
      s -= dot(s, n) * n;  // keep the spring in the current tangent plane
    }
    const R kt = result.kt;
    V ft = -kt * s;
    const R ft_elastic = kt * norm(s);
    const R ft_max = p.mu_s * lane_abs(result.fn_limit);
    // Sticking: the spring plus damping. Sliding: the spring force scaled down to the Coulomb
    // limit, and the spring shortened to match it (no force if the spring is empty).
    const auto sliding = ft_elastic > ft_max;
    const V ft_stick = ft - result.gamma_t * vt;
    if (any(sliding)) {
      const auto stretched = ft_elastic > 0.0;
      const V ft_slide = select(stretched, ft * (ft_max / ft_elastic), V{});
      const V s_slide = select(stretched, -(1.0 / kt) * ft_slide, s);
      ft = select(sliding, ft_slide, ft_stick);
      s = select(sliding, s_slide, s);
    } else {
      ft = ft_stick;
    }
    if (step.update_history) {
      shear[0] = s.x;
      shear[1] = s.y;
      shear[2] = s.z;
    }
    result.force = result.fn * n + ft;
    const V arm = cross(n, ft);
    result.torque_i = -c.cri * arm;
    result.torque_j = -c.crj * arm;
  }
};

}  // namespace dem
