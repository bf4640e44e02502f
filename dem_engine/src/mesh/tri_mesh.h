#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "mesh/mesh_topology.h"
#include "mesh/stl_io.h"
#include "mesh/triangle_geometry.h"

namespace dem {

// A rigid triangle surface mesh: three nodes per triangle (no shared node table, the STL
// "triangle soup"), a velocity per node for moving walls, and reference frames that move with
// the mesh (the origins and axes of superposed motions).
// LIGGGHTS' default curvature of fix mesh/surface (degrees).
constexpr double kDefaultCurvatureDegrees = 0.256235;

class TriMesh {
 public:
  TriMesh() = default;
  // Throws EngineError naming `source` when a triangle has (nearly) zero area.
  TriMesh(const std::vector<Triangle>& triangles, const std::string& source);

  std::size_t size() const { return nodes_.size() / 3; }
  const Vec3& node(std::size_t tri, int k) const { return nodes_[3 * tri + k]; }
  const std::vector<Vec3>& nodes() const { return nodes_; }
  std::vector<Triangle> triangles() const;

  // Closest point of triangle `tri` to p.
  ClosestPoint closest_point(std::size_t tri, const Vec3& p) const {
    return closest_point_on_triangle(p, nodes_[3 * tri], nodes_[3 * tri + 1], nodes_[3 * tri + 2]);
  }
  // Contact point of a sphere centred at p with triangle `tri`, as LIGGGHTS finds it.
  ClosestPoint contact_point(std::size_t tri, const Vec3& p) const {
    return contact_point_on_triangle(p, nodes_[3 * tri], nodes_[3 * tri + 1], nodes_[3 * tri + 2],
                                     planes_[tri], topology_.face_tolerance(tri));
  }
  // Plane of triangle `tri` at the nodes' current positions.
  const TrianglePlane& plane(std::size_t tri) const { return planes_[tri]; }
  // Velocity of the surface at a point given by barycentric weights (m/s). Exact for rigid
  // motions, whose velocity field is affine in the position.
  Vec3 velocity_at(std::size_t tri, const ClosestPoint& cp) const {
    const Vec3* v = &velocities_[3 * tri];
    return cp.wa * v[0] + cp.wb * v[1] + cp.wc * v[2];
  }
  bool moving() const { return moving_; }

  // Active edges and corners and coplanar neighbours for the curvature angle (degrees), see
  // MeshTopology; the constructor uses LIGGGHTS' default of 0.256235 degrees. Throws
  // EngineError naming `source` when the curvature exceeds an angle of a triangle (LIGGGHTS
  // refuses such meshes).
  void set_curvature(double degrees, const std::string& source);
  const MeshTopology& topology() const { return topology_; }

  // Set-up transformations (mesh/surface keywords): about the origin, as LIGGGHTS does.
  void scale(double factor);
  // Rigid motions. Frames with index >= first_frame move along (see add_frame).
  void translate(const Vec3& d, std::size_t first_frame = 0);
  void rotate(const Vec3& unit_axis, double angle, const Vec3& center, std::size_t first_frame = 0);

  // Node velocities: cleared at every step, then each motion adds its own part.
  void clear_velocities();
  void add_velocity(const Vec3& v);
  void add_rotation_velocity(const Vec3& omega, const Vec3& origin);
  double max_node_speed() const;

  // A point and a direction carried along by the motions that act on the mesh before the owner
  // of the frame (superposition of move/mesh: later motions live in the moving frame).
  struct Frame {
    Vec3 origin, axis;
  };
  std::size_t add_frame(const Vec3& origin, const Vec3& axis);
  const Frame& frame(std::size_t k) const { return frames_[k]; }

  // Counts rigid motions, so that users can tell whether the nodes changed.
  long version() const { return version_; }
  void bounding_box(Vec3& lo, Vec3& hi) const;

 private:
  std::vector<Vec3> nodes_;
  std::vector<Vec3> velocities_;
  std::vector<Frame> frames_;
  std::vector<TrianglePlane> planes_;  // one per triangle, renewed by every motion
  MeshTopology topology_;
  long version_ = 0;
  bool moving_ = false;

  void reject_duplicates(const std::string& source) const;
  void update_planes();
};

}  // namespace dem
