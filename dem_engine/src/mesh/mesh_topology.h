#pragma once
#include <cstdint>
#include <vector>

#include "core/vec3.h"

namespace dem {

// Which edges and corners of a triangle soup produce contacts, and which triangles are
// coplanar neighbours, with the rules of LIGGGHTS 3.8 `fix mesh/surface` (determined by running
// it):
// - Nodes closer than the precision (1e-8 m) are one node; triangles sharing two nodes share
//   an edge. Two triangles sharing an edge are coplanar when the angle between their normals,
//   orientation disregarded, is below the curvature angle.
// - An edge shared by coplanar triangles is inactive in both; an edge shared by triangles that
//   are not coplanar is active in the triangle of higher index only; an edge of one triangle
//   is active.
// - A node shared by several triangles is a corner of each of them; triangles connected by
//   shared edges through the node form one group, in which only the triangle of highest index
//   has the corner active (so a sphere touching the node gets one contact per group).
// - A sphere touching a triangle in its face always makes a contact; in an edge or corner
//   region only if that edge or corner is active. A point projecting onto the plane of the
//   triangle counts as in the face while no barycentric coordinate is below
//   -precision / (2 rBound), rBound the largest distance of a node from the centroid.
class MeshTopology {
 public:
  MeshTopology() = default;
  // `nodes` holds three nodes per triangle; `cos_curvature` is the cosine of the curvature.
  MeshTopology(const std::vector<Vec3>& nodes, double cos_curvature);

  // Edge k joins nodes k and (k + 1) % 3 of the triangle; corner k is node k.
  bool edge_active(std::size_t tri, int k) const { return (flags_[tri] >> k) & 1u; }
  bool corner_active(std::size_t tri, int k) const { return (flags_[tri] >> (3 + k)) & 1u; }
  // True when triangles a and b share an edge and are coplanar.
  bool coplanar_neighbours(std::size_t a, std::size_t b) const;
  // How far (in barycentric coordinates) a projection may lie outside the face and count as
  // in it.
  double face_tolerance(std::size_t tri) const { return tolerance_[tri]; }

 private:
  std::vector<std::uint8_t> flags_;     // per triangle: edges (bits 0-2), corners (bits 3-5)
  std::vector<double> tolerance_;       // per triangle
  std::vector<int> neighbour_first_;    // size ntri+1
  std::vector<std::uint32_t> coplanar_;  // coplanar edge neighbours, by triangle
};

// Node identity tolerance of meshes (m), LIGGGHTS' default `precision`.
constexpr double kMeshNodePrecision = 1e-8;

}  // namespace dem
