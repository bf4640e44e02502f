#pragma once
#include <cstdint>
#include <vector>

#include "core/particles.h"
#include "mesh/tri_mesh.h"

namespace dem {

// A candidate triangle of a particle: mesh index (in the order given to build) and triangle.
struct TriRef {
  std::uint32_t mesh = 0;
  std::uint32_t tri = 0;
};

// Per-particle candidate triangles within radius + skin of the particle centre, from a cell
// binning of the particles: each triangle visits only the cells its box (widened by the
// largest radius + skin) overlaps. The list stays valid while every particle and every mesh
// node has moved less than skin/2 since the build, since the particle-triangle distance then
// changes by less than the skin.
class TriangleNeighborList {
 public:
  std::vector<int> first;     // size n+1: candidates of particle i are [first[i], first[i+1])
  std::vector<TriRef> refs;

  // Particles outside `group_bit` get no candidates.
  void build(const Particles& p, std::uint32_t group_bit, const std::vector<const TriMesh*>& meshes,
             double skin);
  // True when a particle or a mesh node moved more than skin/2 since the build, or the
  // particle storage changed (size, order) or the set of meshes changed.
  bool due(const Particles& p, const std::vector<const TriMesh*>& meshes) const;
  void force_rebuild() { forced_ = true; }

  long builds() const { return builds_; }
  // Exact particle-triangle distance evaluations of the last build (cost measure).
  long long last_build_checks() const { return checks_; }

 private:
  std::vector<Vec3> x_at_build_;
  std::vector<std::int64_t> tag_at_build_;
  std::vector<std::vector<Vec3>> nodes_at_build_;
  std::vector<long> mesh_version_at_build_;
  std::vector<const TriMesh*> meshes_at_build_;
  double skin_ = 0.0;
  bool forced_ = true;
  long builds_ = 0;
  long long checks_ = 0;
  // Scratch storage of the build, kept to avoid reallocation.
  std::vector<int> cell_start_, cell_items_, pair_particle_;
  std::vector<TriRef> pair_ref_;
};

}  // namespace dem
