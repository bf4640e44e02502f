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
// changes by less than the skin. Between builds it also bounds each candidate's distance at the
// step itself, from the build's distance and how far the particle and the mesh have moved
// (find_mesh_contacts with CandidateMotion).
class TriangleNeighborList {
 public:
  std::vector<int> first;     // size n+1: candidates of particle i are [first[i], first[i+1])
  std::vector<TriRef> refs;
  // Per candidate, parallel to refs: a lower bound, at the build, of the distance from the
  // particle centre to its contact point on the triangle (m): the closest point's distance less
  // how far a projection that counts as in the face (MeshTopology::face_tolerance) may lie
  // outside the triangle.
  std::vector<double> dist;

  // Particles outside `group_bit` get no candidates.
  void build(const Particles& p, std::uint32_t group_bit, const std::vector<const TriMesh*>& meshes,
             double skin);
  // True when a particle or a mesh node moved more than skin/2 since the build, or the
  // particle storage changed (size, order) or the set of meshes changed. When false it has
  // measured, on the way, how far each particle and mesh moved since the build (moved2,
  // mesh_shift).
  bool due(const Particles& p, const std::vector<const TriMesh*>& meshes);
  void force_rebuild() { forced_ = true; }
  // As of the last build or the last due() that returned false: the squared distance particle
  // i has moved since the build (m^2), and per mesh of the build the farthest any of its nodes
  // has moved (m).
  double moved2(std::size_t i) const { return moved2_[i]; }
  const std::vector<double>& mesh_shift() const { return mesh_shift_; }

  long builds() const { return builds_; }
  // Exact particle-triangle distance evaluations of the last build (cost measure).
  long long last_build_checks() const { return checks_; }

 private:
  std::vector<Vec3> x_at_build_;
  std::vector<std::int64_t> tag_at_build_;
  std::vector<std::vector<Vec3>> nodes_at_build_;
  std::vector<long> mesh_version_at_build_;
  std::vector<double> moved2_, mesh_shift_;
  std::vector<const TriMesh*> meshes_at_build_;
  double skin_ = 0.0;
  bool forced_ = true;
  long builds_ = 0;
  long long checks_ = 0;
  // Scratch storage of the build, kept to avoid reallocation.
  std::vector<int> cell_start_, cell_items_, pair_particle_;
  std::vector<TriRef> pair_ref_;
  std::vector<double> pair_dist_;
};

}  // namespace dem
