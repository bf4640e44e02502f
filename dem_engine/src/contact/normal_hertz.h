#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Hertz normal contact with restitution-based damping (LIGGGHTS `model hertz`).
// Sets fn (and fn_limit to it), kn, kt and gamma_t.
struct NormalHertz {
  static void apply(const ContactInput& c, const PairParams& p, const ContactStep& step,
                    double* /*history*/, ContactResult& result) {
    const double sqrt_rd = std::sqrt(c.r_eff * c.overlap);
    const double sn = 2.0 * p.y_star * sqrt_rd;
    const double st = 8.0 * p.g_star * sqrt_rd;
    const double kn = 4.0 / 3.0 * p.y_star * sqrt_rd;
    constexpr double k56 = 1.8257418583505538;  // 2 sqrt(5/6)
    const double gamma_n = -k56 * p.beta * std::sqrt(sn * c.m_eff);
    const double gamma_t = -k56 * p.beta * std::sqrt(st * c.m_eff);
    const double vn = dot(c.v_rel, c.n);
    double fn = kn * c.overlap - gamma_n * vn;
    if (step.options.limit_force && fn < 0.0) fn = 0.0;
    result.fn = fn;
    result.fn_limit = fn;
    result.kn = kn;
    result.kt = st;
    result.gamma_t = step.options.tangential_damping ? gamma_t : 0.0;
  }
};

}  // namespace dem
