#include "mesh/primitive_wall.h"

#include <cmath>

#include "core/numbers.h"
#include "deck/errors.h"

namespace dem {

bool PrimitiveWall::is_style(const std::string& w) {
  return w == "xplane" || w == "yplane" || w == "zplane" || w == "xcylinder" ||
         w == "ycylinder" || w == "zcylinder";
}

PrimitiveWall PrimitiveWall::parse(const std::vector<std::string>& words, std::size_t& pos) {
  if (pos >= words.size() || !is_style(words[pos]))
    throw EngineError("expected xplane, yplane, zplane, xcylinder, ycylinder or zcylinder, got '" +
                      (pos < words.size() ? words[pos] : std::string("end of line")) + "'");
  const std::string& w = words[pos];
  PrimitiveWall wall;
  wall.dim = w[0] - 'x';
  if (w.substr(1) == "plane") {
    if (pos + 1 >= words.size()) throw EngineError(w + " needs a position");
    wall.kind = Kind::kPlane;
    wall.position = parse_double(words[pos + 1], w + " position");
    pos += 2;
  } else {
    if (pos + 3 >= words.size()) throw EngineError(w + " needs RADIUS C1 C2");
    wall.kind = Kind::kCylinder;
    wall.radius = parse_double(words[pos + 1], w + " radius");
    if (!(wall.radius > 0.0)) throw EngineError(w + " radius must be > 0, got " + words[pos + 1]);
    wall.c1 = parse_double(words[pos + 2], w + " axis coordinate 1");
    wall.c2 = parse_double(words[pos + 3], w + " axis coordinate 2");
    pos += 4;
  }
  return wall;
}

bool PrimitiveWall::contact(const Vec3& x, double reach, Vec3& normal, double& dist) const {
  if (kind == Kind::kPlane) {
    const double d = x[dim] - position;
    dist = std::fabs(d);
    if (dist >= reach) return false;
    normal = Vec3{};
    normal[dim] = d >= 0.0 ? 1.0 : -1.0;
    return true;
  }
  const int d1 = (dim + 1) % 3, d2 = (dim + 2) % 3;  // cyclic: (y, z), (z, x), (x, y)
  const double u = x[d1] - c1, v = x[d2] - c2;
  const double rho = std::sqrt(u * u + v * v);
  dist = std::fabs(radius - rho);
  if (dist >= reach || rho == 0.0) return false;
  // Radial unit vector; inside the cylinder the wall pushes towards the axis.
  const double s = (rho < radius ? -1.0 : 1.0) / rho;
  normal = Vec3{};
  normal[d1] = s * u;
  normal[d2] = s * v;
  return true;
}

}  // namespace dem
