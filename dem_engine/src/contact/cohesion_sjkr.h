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
  static double contact_area(const ContactInput& c) {
    if (c.wall) return M_PI * (c.ri * c.ri - c.dist * c.dist);
    const double r = c.dist;
    const double prod =
        (r - c.ri - c.rj) * (r + c.ri - c.rj) * (r - c.ri + c.rj) * (r + c.ri + c.rj);
    return 0.25 * M_PI * std::fabs(prod) / (r * r);
  }
  static void apply(const ContactInput& c, const PairParams& p, const ContactStep& step,
                    double* /*history*/, ContactResult& result) {
    if (p.cohesion <= 0.0) return;
    const double f = p.cohesion * contact_area(c);
    result.fn -= f;
    if (step.options.tangential_reduce) result.fn_limit -= f;
  }
};

}  // namespace dem
