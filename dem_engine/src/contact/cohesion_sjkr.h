#pragma once
#include <cmath>

#include "contact/contact_types.h"

namespace dem {

// Simplified JKR cohesion (LIGGGHTS `cohesion sjkr`): attractive normal force k A while the
// particles overlap; A is the area of the intersection circle of the two spheres.
struct CohesionSjkr {
  static double contact_area(const ContactInput& c) {
    if (c.wall) return M_PI * (c.ri * c.ri - c.dist * c.dist);
    const double r = c.dist;
    const double prod =
        (r - c.ri - c.rj) * (r + c.ri - c.rj) * (r - c.ri + c.rj) * (r + c.ri + c.rj);
    return 0.25 * M_PI * std::fabs(prod) / (r * r);
  }
  static void apply(const ContactInput& c, const PairParams& p, ContactResult& result) {
    if (p.cohesion <= 0.0) return;
    result.fn -= p.cohesion * contact_area(c);
  }
};

}  // namespace dem
