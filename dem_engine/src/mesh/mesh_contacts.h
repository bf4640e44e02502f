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

// Contacts of the sphere (x, r) with the candidate triangles refs[0..n): every triangle whose
// closest point lies closer than r, then the redundant ones removed (see
// remove_redundant_contacts). `out` is cleared first.
void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out);

// A rigid surface touches a sphere once per feature, but a triangle soup reports an edge or a
// vertex once for every triangle that shares it, and reports the edge of a neighbouring
// triangle although the sphere already touches that neighbour's face (flat plates, convex
// bends). An edge or vertex contact c is therefore dropped when another contact c' is at
// least as close (ties broken by face first, then by position in the list) and c's contact
// point lies on the triangle of c' (within `tol`, m): then the feature of c belongs to the
// triangle of c', whose closest point already is the closest point of the surface there.
// Face contacts are never dropped, so a sphere in a concave corner keeps one contact per face.
void remove_redundant_contacts(std::vector<MeshContact>& contacts,
                               const std::vector<const TriMesh*>& meshes, double tol);

// Contact history of one particle with the meshes of one wall: kMeshSlots slots of
// [key, normal (3), history (kHistorySize)]; key 0 marks a free slot.
constexpr int kMeshSlots = 8;
constexpr int kMeshSlotWidth = 4 + kHistorySize;

// Assigns a history (kHistorySize doubles) to every contact of one particle: the slot of the
// same triangle if it was touching at the previous step; otherwise the slot of a triangle of
// the same mesh that stopped touching now and whose contact normal is within the curvature
// angle of that mesh, so the tangential spring survives crossing a flat or gently bent
// edge; otherwise a fresh zero history. Slots of contacts that opened are cleared. Contacts
// beyond kMeshSlots get a zero history in `overflow` (kHistorySize doubles each) that is not
// kept; returns the number of such contacts.
// `cos_curvature` is indexed by mesh.
int assign_history_slots(double* slots, const std::vector<MeshContact>& contacts,
                         const std::vector<double>& cos_curvature, std::vector<double*>& history,
                         double* overflow);

}  // namespace dem
