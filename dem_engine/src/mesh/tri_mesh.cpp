#include "mesh/tri_mesh.h"

#include <algorithm>
#include <array>
#include <utility>
#include <cmath>

#include "deck/errors.h"

namespace dem {

TriMesh::TriMesh(const std::vector<Triangle>& triangles, const std::string& source) {
  if (triangles.empty()) throw EngineError("mesh from " + source + " has no triangles");
  nodes_.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t].v;
    // Zero-area facets have no normal; relative to the longest edge so the test is unit-free.
    const double longest = std::max({norm(v[1] - v[0]), norm(v[2] - v[1]), norm(v[0] - v[2])});
    if (!(triangle_area(v[0], v[1], v[2]) > 1e-12 * longest * longest))
      throw EngineError("mesh from " + source + ": triangle " + std::to_string(t + 1) +
                        " is degenerate (zero area)");
    for (const Vec3& p : v) nodes_.push_back(p);
  }
  velocities_.assign(nodes_.size(), Vec3{});
  update_planes();
  reject_duplicates(source);
  set_curvature(kDefaultCurvatureDegrees, source);
}

void TriMesh::set_curvature(double degrees, const std::string& source) {
  for (std::size_t t = 0; t < size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = node(t, (k + 1) % 3) - node(t, k), w = node(t, (k + 2) % 3) - node(t, k);
      const double angle = std::acos(std::clamp(dot(u, w) / (norm(u) * norm(w)), -1.0, 1.0));
      if (degrees * M_PI / 180.0 > angle)
        throw EngineError("mesh from " + source + ": the curvature " + std::to_string(degrees) +
                          " degrees exceeds the angle of " +
                          std::to_string(angle * 180.0 / M_PI) + " degrees of triangle " +
                          std::to_string(t + 1) + " (LIGGGHTS refuses this)");
    }
  topology_ = MeshTopology(nodes_, std::cos(degrees * M_PI / 180.0));
}

void TriMesh::reject_duplicates(const std::string& source) const {
  // Two copies of a facet would double the wall force. Facets are compared by their vertices
  // in sorted order, so the vertex order and orientation do not matter.
  using Key = std::array<double, 9>;
  const std::size_t n = size();
  std::vector<std::pair<Key, std::size_t>> keys(n);
  for (std::size_t t = 0; t < n; ++t) {
    std::array<Vec3, 3> v{node(t, 0), node(t, 1), node(t, 2)};
    std::sort(v.begin(), v.end(), [](const Vec3& a, const Vec3& b) {
      return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
    });
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) keys[t].first[3 * k + d] = v[k][d];
    keys[t].second = t;
  }
  std::sort(keys.begin(), keys.end());
  // Nodes closer than this are the same node (LIGGGHTS' default mesh precision).
  constexpr double kPrecision = 1e-8;
  for (std::size_t k = 1; k < n; ++k) {
    bool same = true;
    for (int d = 0; d < 9 && same; ++d)
      same = std::fabs(keys[k].first[d] - keys[k - 1].first[d]) <= kPrecision;
    if (same) {
      const auto [a, b] = std::minmax(keys[k - 1].second, keys[k].second);
      throw EngineError("mesh from " + source + ": triangles " + std::to_string(a + 1) + " and " +
                        std::to_string(b + 1) + " are duplicates");
    }
  }
}

std::vector<Triangle> TriMesh::triangles() const {
  std::vector<Triangle> out(size());
  for (std::size_t t = 0; t < out.size(); ++t)
    for (int k = 0; k < 3; ++k) out[t].v[k] = node(t, k);
  return out;
}

void TriMesh::update_planes() {
  // Recomputed from the moved nodes rather than carried along, so that the planes are what the
  // nodes give, to the last bit, after any number of motions.
  planes_.resize(size());
  for (std::size_t t = 0; t < size(); ++t)
    planes_[t] = triangle_plane(node(t, 0), node(t, 1), node(t, 2));
}

void TriMesh::scale(double factor) {
  for (Vec3& p : nodes_) p *= factor;
  update_planes();
  ++version_;
}

void TriMesh::translate(const Vec3& d, std::size_t first_frame) {
  for (Vec3& p : nodes_) p += d;
  for (std::size_t k = first_frame; k < frames_.size(); ++k) frames_[k].origin += d;
  update_planes();
  ++version_;
}

void TriMesh::rotate(const Vec3& unit_axis, double angle, const Vec3& center,
                     std::size_t first_frame) {
  const double cs = std::cos(angle), sn = std::sin(angle);  // once, not per node
  for (Vec3& p : nodes_) p = center + rotate_about_axis(p - center, unit_axis, cs, sn);
  for (std::size_t k = first_frame; k < frames_.size(); ++k) {
    frames_[k].origin = center + rotate_about_axis(frames_[k].origin - center, unit_axis, cs, sn);
    frames_[k].axis = rotate_about_axis(frames_[k].axis, unit_axis, cs, sn);
  }
  update_planes();
  ++version_;
}

void TriMesh::clear_velocities() {
  std::fill(velocities_.begin(), velocities_.end(), Vec3{});
  moving_ = false;
}

void TriMesh::add_velocity(const Vec3& v) {
  for (Vec3& u : velocities_) u += v;
  moving_ = true;
}

void TriMesh::add_rotation_velocity(const Vec3& omega, const Vec3& origin) {
  for (std::size_t k = 0; k < nodes_.size(); ++k)
    velocities_[k] += cross(omega, nodes_[k] - origin);
  moving_ = true;
}

double TriMesh::max_node_speed() const {
  double v2 = 0.0;
  for (const Vec3& u : velocities_) v2 = std::max(v2, norm2(u));
  return std::sqrt(v2);
}

std::size_t TriMesh::add_frame(const Vec3& origin, const Vec3& axis) {
  frames_.push_back({origin, axis});
  return frames_.size() - 1;
}

void TriMesh::bounding_box(Vec3& lo, Vec3& hi) const {
  lo = Vec3{1e300, 1e300, 1e300};
  hi = Vec3{-1e300, -1e300, -1e300};
  for (const Vec3& p : nodes_)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
}

}  // namespace dem
