#pragma once
#include <array>

#include "core/vec3.h"

namespace dem {

// Simulation box. Boundary per dimension: 'p' periodic, 'f' fixed (particles leaving are lost),
// 'm' / 's' shrink-wrapped (the box follows the particles; 'm' never shrinks below the initial box).
struct Domain {
  Vec3 lo{0, 0, 0}, hi{1, 1, 1};
  std::array<char, 3> boundary{'p', 'p', 'p'};
  bool defined = false;

  bool periodic(int dim) const { return boundary[dim] == 'p'; }
  Vec3 length() const { return hi - lo; }
  // Minimum-image displacement for periodic dimensions.
  Vec3 minimum_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k)
      if (periodic(k)) {
        const double len = hi[k] - lo[k];
        if (d[k] > 0.5 * len) d[k] -= len;
        else if (d[k] < -0.5 * len) d[k] += len;
      }
    return d;
  }
};

}  // namespace dem
