#pragma once
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
ClosestPoint contact_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                       const TrianglePlane& plane, double tolerance);

// Unit normal (b - a) x (c - a) / |...|; the zero vector for a degenerate triangle.
Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c);
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);

// Rotates v by `angle` (rad) about the unit axis `unit_axis` through the origin (right hand).
Vec3 rotate_about_axis(const Vec3& v, const Vec3& unit_axis, double angle);

}  // namespace dem
