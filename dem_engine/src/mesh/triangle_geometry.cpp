#include "mesh/triangle_geometry.h"

#include <algorithm>
#include <cmath>

namespace dem {

ClosestPoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                       const Vec3& c) {
  // Region tests on the projections of p onto the edge directions (Voronoi regions of the
  // vertices, then of the edges, otherwise the face); every branch only divides by a quantity
  // that its own test has shown to be positive.
  ClosestPoint r;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    r.point = a;
    r.region = TriRegion::kVertexA;
    return r;
  }
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) {
    r.point = b;
    r.wa = 0.0;
    r.wb = 1.0;
    r.region = TriRegion::kVertexB;
    return r;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double t = d1 - d3 > 0.0 ? d1 / (d1 - d3) : 0.0;
    r.point = a + t * ab;
    r.wa = 1.0 - t;
    r.wb = t;
    r.region = TriRegion::kEdgeAB;
    return r;
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) {
    r.point = c;
    r.wa = 0.0;
    r.wc = 1.0;
    r.region = TriRegion::kVertexC;
    return r;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double t = d2 - d6 > 0.0 ? d2 / (d2 - d6) : 0.0;
    r.point = a + t * ac;
    r.wa = 1.0 - t;
    r.wc = t;
    r.region = TriRegion::kEdgeCA;
    return r;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double s = (d4 - d3) + (d5 - d6);
    const double t = s > 0.0 ? (d4 - d3) / s : 0.0;
    r.point = b + t * (c - b);
    r.wa = 0.0;
    r.wb = 1.0 - t;
    r.wc = t;
    r.region = TriRegion::kEdgeBC;
    return r;
  }
  const double denom = va + vb + vc;
  if (!(denom > 0.0)) {  // degenerate triangle that slipped through: nearest vertex
    r.point = a;
    return r;
  }
  const double v = vb / denom, w = vc / denom;
  r.point = a + v * ab + w * ac;
  r.wa = 1.0 - v - w;
  r.wb = v;
  r.wc = w;
  r.region = TriRegion::kFace;
  return r;
}

TrianglePlane triangle_plane(const Vec3& a, const Vec3& b, const Vec3& c) {
  TrianglePlane t;
  t.n = cross(b - a, c - a);
  t.area2 = norm2(t.n);
  if (!(t.area2 > 0.0)) return t;
  // The weight of a at q in the plane is the area of (q, b, c) over that of (a, b, c):
  // ((c - b) x (q - b)) . n / |n|^2 = (q - b) . (n x (c - b)) / |n|^2; likewise for b and c.
  const double inv = 1.0 / t.area2;
  t.grad[0] = inv * cross(t.n, c - b);
  t.grad[1] = inv * cross(t.n, a - c);
  t.grad[2] = inv * cross(t.n, b - a);
  return t;
}

Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = cross(b - a, c - a);
  const double len = norm(n);
  return len > 0.0 ? (1.0 / len) * n : Vec3{};
}

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * norm(cross(b - a, c - a));
}

Vec3 rotate_about_axis(const Vec3& v, const Vec3& k, double cs, double sn) {
  // Rodrigues' formula.
  return cs * v + sn * cross(k, v) + (dot(k, v) * (1.0 - cs)) * k;
}

}  // namespace dem
