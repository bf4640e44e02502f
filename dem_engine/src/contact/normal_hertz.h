#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Hertz normal contact with restitution-based damping (LIGGGHTS `model hertz`).
// Sets fn (and fn_limit to it), kn, kt and gamma_t.
struct NormalHertz {
  template <class R>
  DEM_INLINE static void apply(const ContactInputT<R>& c, const PairParamsT<R>& p,
                               const ContactStep& step, R* /*history*/, ContactResultT<R>& result) {
    const R sqrt_rd = lane_sqrt(c.r_eff * c.overlap);
    const R sn = 2.0 * p.y_star * sqrt_rd;
    const R st = 8.0 * p.g_star * sqrt_rd;
    const R kn = 4.0 / 3.0 * p.y_star * sqrt_rd;
    constexpr double k56 = 1.8257418583505538;  // 2 sqrt(5/6)
    const R gamma_n = -k56 * p.beta * lane_sqrt(sn * c.m_eff);
    const R gamma_t = -k56 * p.beta * lane_sqrt(st * c.m_eff);
    const R vn = dot(c.v_rel, c.n);
    R fn = kn * c.overlap - gamma_n * vn;
    if (step.options.limit_force) fn = select(fn < 0.0, R(0.0), fn);
    result.fn = fn;
    result.fn_limit = fn;
    result.kn = kn;
    result.kt = st;
    result.gamma_t = step.options.tangential_damping ? gamma_t : R(0.0);
  }
};

}  // namespace dem
