#pragma once
#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "fix/fix.h"
#include "mesh/fix_mesh_surface.h"
#include "mesh/mesh_contacts.h"
#include "mesh/primitive_wall.h"
#include "mesh/tri_neighbor_list.h"

namespace dem {

// fix ID group wall/gran model hertz tangential history [cohesion sjkr] [rolling_friction epsd2]
//     primitive type T xplane|yplane|zplane C [model keywords]
// fix ID group wall/gran ... primitive type T xcylinder|ycylinder|zcylinder R C1 C2 [...]
// fix ID group wall/gran ... mesh n_meshes N meshes ID1 ... IDN [...]
// Granular walls with the contact law of pair_style gran (the model words must match it).
// Particles of the group interact with the wall from the side their centre is on; forces and
// torques are added in post_force. One contact history per particle and contact (primitive:
// one; mesh: up to kMeshSlots, see assign_history_slots) lives in per-particle storage and is
// cleared when the contact opens; with meshes a per-particle record of the slots in use lets
// the particles that hold none skip their slots. Primitive-wall candidates are the particles
// near the wall at the last neighbour build; mesh candidates come from a TriangleNeighborList
// rebuilt when particles or meshes moved more than skin/2.
class FixWallGran : public Fix {
 public:
  FixWallGran(Simulation& sim, const Command& command);
  void init() override;
  HookWork post_force_work() override;

  const TriangleNeighborList& triangle_list() const { return list_; }
  bool mesh_mode() const { return mesh_mode_; }

 private:
  void check_model() const;
  void check_single_mesh_wall() const;
  void primitive_share(std::size_t begin, std::size_t end);
  void find_near_primitive();
  void mesh_forces();
  void finish_step(double worst_ratio, long worst_tag, long overflow);

  ModelSpec spec_;
  bool mesh_mode_ = false;
  // primitive
  PrimitiveWall wall_;
  int wall_type_ = 0;
  // Particles within reach of the primitive wall at the last neighbour build (all others are
  // too far to touch it before the next build).
  std::vector<std::size_t> near_;
  long near_builds_ = -1;
  std::size_t near_count_of_ = 0;
  // This step's deepest overlap with the primitive wall over the shares so far, and its particle.
  double worst_ = 0.0;
  long worst_tag_ = -1;
  // mesh
  std::vector<std::string> mesh_ids_;
  std::vector<FixMeshSurface*> mesh_fixes_;  // refreshed at every init
  std::vector<const TriMesh*> meshes_;
  TriangleNeighborList list_;
  // The build of list_ the last step ran with: while it stays the same, a particle without
  // candidate triangles had none at that step either, so its history slots are already free.
  long slots_checked_for_build_ = -1;
  std::vector<std::uint32_t> stress_bits_;  // per mesh: group bit if it tracks stress, else 0
  std::vector<Vec3> reference_;             // per mesh: torque reference point
  std::size_t history_ = 0;                 // Particles extra handle
  // Particles extra handle: per particle, a bit per history slot holding a contact (mesh mode;
  // live_slots of its slots, kept by assign_history_slots and release_slots). An extra, so that
  // it moves with the slots when particles are added, removed or reordered.
  std::size_t live_ = 0;
  bool overflow_warned_ = false;

  struct Scratch {
    std::vector<MeshContact> contacts;
    std::vector<double*> history;
    std::vector<double> overflow;
    std::vector<Vec3> force, torque;  // per mesh: load on the mesh
  };
  std::vector<Scratch> scratch_;  // per thread
};

}  // namespace dem
