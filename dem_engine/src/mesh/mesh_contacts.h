#pragma once
#include <cstdint>
#include <vector>

#include "contact/contact_types.h"
#include "mesh/tri_mesh.h"
#include "mesh/tri_neighbor_list.h"

namespace dem {

// One sphere-triangle contact.
struct MeshContact {
  std::uint32_t mesh = 0, tri = 0;
  ClosestPoint cp;  // contact point on the triangle and its feature
  Vec3 normal;      // unit vector from the contact point to the sphere centre
  double dist = 0;  // centre to contact point (m), < radius
};

// Contacts of the sphere (x, r) with the candidate triangles refs[0..n), taken in order (by
// mesh, then triangle): every triangle whose contact point (as LIGGGHTS finds it) lies closer
// than r, in its face or on an active edge or corner (MeshTopology). `out` is cleared first.
// assign_history_slots then drops the contacts LIGGGHTS does not make.
void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out);

// What the candidate list (TriangleNeighborList) knows of a particle's candidates: lower bounds
// of their contact distances at the list's build, and how far the particle and the nodes of
// each mesh have moved since (m).
struct CandidateMotion {
  const double* dist = nullptr;        // per candidate, TriangleNeighborList::dist
  double moved = 0.0;                  // the particle
  const double* mesh_shift = nullptr;  // per mesh
};

// The same contacts in the same order, but candidates that cannot touch are passed over without
// reading their triangles: no point of a triangle moves farther than its farthest node, so a
// contact distance falls by at most the particle's and the nodes' motions since the build, and
// a candidate whose bound, less both, still exceeds r is out of reach. The list holds every
// triangle within r + skin, so in a dense packing most candidates end here (two in three in a
// ring shear cell).
void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out,
                        const CandidateMotion& motion);

// Contact history of one particle with the meshes of one wall: kMeshSlots slots of
// [key, history (kHistorySize)]; key 0 marks a free slot.
constexpr int kMeshSlots = 8;
constexpr int kMeshSlotWidth = 1 + kHistorySize;
static_assert(kMeshSlots <= 32, "a bit per slot in a 32-bit word");

// Decides which contacts of one particle act and assigns them a history (kHistorySize
// doubles), with LIGGGHTS' rules, taking `contacts` in order:
// - a contact with a triangle that was touching at the previous step acts and keeps its
//   history;
// - a new contact does not act (it is removed from `contacts`) when a coplanar neighbour of
//   its triangle already acts at this step; otherwise it acts, with a copy of the history of
//   a previous-step contact with a coplanar neighbour of its triangle if there is one (the
//   contact moved across a flat or gently bent edge), else with a zero history.
// Slots of contacts that opened are cleared. Contacts beyond kMeshSlots get a zero history in
// `overflow` (kHistorySize doubles each) that is not kept; returns the number of such contacts.
// `live` has bit s set exactly when slot s has a non-zero key, before and after: only those
// slots are read, so a particle with one or two contacts touches one or two of its slots.
int assign_history_slots(double* slots, std::uint32_t& live, std::vector<MeshContact>& contacts,
                         const std::vector<const TriMesh*>& meshes, std::vector<double*>& history,
                         double* overflow);
// The same, with the live slots read from the keys.
int assign_history_slots(double* slots, std::vector<MeshContact>& contacts,
                         const std::vector<const TriMesh*>& meshes, std::vector<double*>& history,
                         double* overflow);
// Bit s set when slot s of `slots` holds a contact (a non-zero key).
std::uint32_t live_slots(const double* slots);
// Frees the slots of `live` (fills them with zeros); `live` becomes 0.
void release_slots(double* slots, std::uint32_t& live);

}  // namespace dem
