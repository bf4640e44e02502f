#pragma once
#include <string>
#include <vector>

#include "core/vec3.h"

namespace dem {

// Geometry of the primitive walls of fix wall/gran: a plane normal to x, y or z at `position`,
// or an infinite cylinder along x, y or z of `radius` whose axis passes through (c1, c2) in the
// other two dimensions, in cyclic order as LIGGGHTS 3.8 reads them: xcylinder (y, z),
// ycylinder (z, x), zcylinder (x, y).
// Walls act from the side the particle centre is on.
struct PrimitiveWall {
  enum class Kind { kPlane, kCylinder };
  Kind kind = Kind::kPlane;
  int dim = 2;            // normal (plane) or axis (cylinder) direction: 0 x, 1 y, 2 z
  double position = 0.0;  // plane position (m)
  double radius = 0.0;    // cylinder radius (m)
  double c1 = 0.0, c2 = 0.0;

  // Parses "xplane C", "zcylinder R C1 C2", ... starting at words[pos]; returns the index after.
  static PrimitiveWall parse(const std::vector<std::string>& words, std::size_t& pos);
  static bool is_style(const std::string& word);

  // Distance from the centre x to the wall (m) and the unit normal from the wall towards x.
  // Returns false when the distance is not below `reach`.
  bool contact(const Vec3& x, double reach, Vec3& normal, double& dist) const;
};

}  // namespace dem
