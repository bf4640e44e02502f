#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Simplified JKR cohesion (LIGGGHTS `cohesion sjkr`): attractive normal force k A while the
// particles overlap; A is the area of the intersection circle of the two spheres (against a
// wall, of the sphere with the wall plane). The force bounding friction and rolling resistance
// keeps the contact force alone unless `tangential_reduce on`, which subtracts the cohesive
// force from it as well.
struct CohesionSjkr {
  template <class R>
  DEM_INLINE static R contact_area(const ContactInputT<R>& c) {
    if (c.wall) return M_PI * (c.ri * c.ri - c.dist * c.dist);
    const R r = c.dist;
    const R prod =
        (r - c.ri - c.rj) * (r + c.ri - c.rj) * (r - c.ri + c.rj) * (r + c.ri + c.rj);
    return 0.25 * M_PI * lane_abs(prod) / (r * r);
  }
  template <class R>
  DEM_INLINE static void apply(const ContactInputT<R>& c, const PairParamsT<R>& p,
                               const ContactStep& step, R* /*history*/, ContactResultT<R>& result) {
    const auto cohesive = p.cohesion > 0.0;
    if (!any(cohesive)) return;
    const R f = p.cohesion * contact_area(c);
    result.fn = select(cohesive, result.fn - f, result.fn);
    if (step.options.tangential_reduce)
      result.fn_limit = select(cohesive, result.fn_limit - f, result.fn_limit);
  }
};

}  // namespace dem
