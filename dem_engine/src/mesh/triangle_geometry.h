#pragma once
#include <algorithm>

#include "core/vec3.h"

namespace dem {

// Which feature of a triangle (a, b, c) holds the point closest to a query point.
enum class TriRegion : unsigned char {
  kFace,     // interior of the face
  kEdgeAB,   // interior of edge a-b
  kEdgeBC,   // interior of edge b-c
  kEdgeCA,   // interior of edge c-a
  kVertexA,
  kVertexB,
  kVertexC,
};

// Closest point of a triangle to a query point, with its barycentric weights (wa + wb + wc = 1)
// so that node quantities (e.g. velocities) can be interpolated at that point.
struct ClosestPoint {
  Vec3 point;
  double wa = 1.0, wb = 0.0, wc = 0.0;
  TriRegion region = TriRegion::kVertexA;
  bool on_face() const { return region == TriRegion::kFace; }
};

// Closest point on the (closed) triangle a, b, c to p, classified by Voronoi region of the
// triangle's features. Degenerate triangles are handled (the result is a point of a segment).
ClosestPoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// What contact_point_on_triangle needs of a triangle a, b, c besides its nodes, fixed while the
// triangle keeps its shape and orientation: with it a query costs dot products only.
struct TrianglePlane {
  Vec3 n;              // (b - a) x (c - a) (m^2)
  double area2 = 0.0;  // |n|^2, zero for a degenerate triangle (m^4)
  // Gradients of the barycentric weights of a, b and c in the plane (1/m): the weight of a is
  // (p - b) . grad[0], of b (p - c) . grad[1], of c (p - a) . grad[2], for any p (the part of
  // p - x along n does not count).
  Vec3 grad[3];
};
TrianglePlane triangle_plane(const Vec3& a, const Vec3& b, const Vec3& c);

// The contact point of a sphere centred at p with the triangle as LIGGGHTS 3.8 finds it, from the
// barycentric coordinates of p projected onto the plane of the triangle, counting those below
// -tolerance as negative: none negative, the projection (face); one negative, the closest point
// of the opposite edge (kEdge..., also when that is one of its end points); two negative, the
// remaining vertex. Differs from closest_point_on_triangle in the region reported, at obtuse
// angles in the point, and within the tolerance of an edge. Degenerate triangles give their
// first vertex. `plane` is triangle_plane(a, b, c), computed beforehand.
// Inline: the mesh contact search calls it for every candidate triangle near its plane.
inline ClosestPoint contact_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                              const Vec3& c, const TrianglePlane& plane,
                                              double tolerance) {
  ClosestPoint r;
  r.point = a;
  if (!(plane.area2 > 0.0)) return r;
  const double w[3] = {dot(p - b, plane.grad[0]), dot(p - c, plane.grad[1]),
                       dot(p - a, plane.grad[2])};
  const Vec3* v[3] = {&a, &b, &c};
  const double lim = -tolerance;
  const int negative = (w[0] < lim) + (w[1] < lim) + (w[2] < lim);
  if (negative == 0) {
    r.point = p - (dot(p - a, plane.n) / plane.area2) * plane.n;  // projection onto the plane
    r.wa = w[0];
    r.wb = w[1];
    r.wc = w[2];
    r.region = TriRegion::kFace;
    return r;
  }
  if (negative == 1) {
    // Edge opposite the negative coordinate, from node (k + 1) % 3 to node (k + 2) % 3.
    const int k = w[0] < lim ? 0 : (w[1] < lim ? 1 : 2);
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Vec3 e = *v[j] - *v[i];
    const double t = std::clamp(dot(p - *v[i], e) / norm2(e), 0.0, 1.0);
    r.point = *v[i] + t * e;
    // Weight 1 - t at node i, t at node j (not through an array indexed by i and j: its
    // element-wise stores and whole reads would stall the store forwarding).
    auto weight = [&](int node) { return node == i ? 1.0 - t : (node == j ? t : 0.0); };
    r.wa = weight(0);
    r.wb = weight(1);
    r.wc = weight(2);
    static constexpr TriRegion kEdgeFrom[3] = {TriRegion::kEdgeAB, TriRegion::kEdgeBC,
                                              TriRegion::kEdgeCA};
    r.region = kEdgeFrom[i];
    return r;
  }
  const int k = w[0] >= lim ? 0 : (w[1] >= lim ? 1 : 2);
  static constexpr TriRegion kVertex[3] = {TriRegion::kVertexA, TriRegion::kVertexB,
                                           TriRegion::kVertexC};
  r.point = *v[k];
  r.wa = k == 0 ? 1.0 : 0.0;
  r.wb = k == 1 ? 1.0 : 0.0;
  r.wc = k == 2 ? 1.0 : 0.0;
  r.region = kVertex[k];
  return r;
}

// Unit normal (b - a) x (c - a) / |...|; the zero vector for a degenerate triangle.
Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c);
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);

// Rotates v about the unit axis `unit_axis` through the origin (right hand) by the angle whose
// cosine and sine are given (computed once for the many vectors one motion turns).
Vec3 rotate_about_axis(const Vec3& v, const Vec3& unit_axis, double cos_angle, double sin_angle);

}  // namespace dem
