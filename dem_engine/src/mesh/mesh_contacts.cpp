#include "mesh/mesh_contacts.h"

#include <algorithm>
#include <cmath>

namespace dem {

namespace {

constexpr double kMeshKeyBase = 4294967296.0;

double slot_key(const MeshContact& c) {
  // Exact in a double (below 2^53); +1 keeps 0 free for "empty".
  return static_cast<double>(c.mesh) * kMeshKeyBase + static_cast<double>(c.tri) + 1.0;
}

std::uint32_t mesh_of_key(double key) {
  return static_cast<std::uint32_t>(std::floor((key - 1.0) / kMeshKeyBase));
}

std::uint32_t tri_of_key(double key) {
  return static_cast<std::uint32_t>(key - 1.0 - mesh_of_key(key) * kMeshKeyBase);
}

bool feature_active(const MeshTopology& topo, std::size_t tri, TriRegion region) {
  switch (region) {
    case TriRegion::kFace: return true;
    case TriRegion::kEdgeAB: return topo.edge_active(tri, 0);
    case TriRegion::kEdgeBC: return topo.edge_active(tri, 1);
    case TriRegion::kEdgeCA: return topo.edge_active(tri, 2);
    case TriRegion::kVertexA: return topo.corner_active(tri, 0);
    case TriRegion::kVertexB: return topo.corner_active(tri, 1);
    case TriRegion::kVertexC: return topo.corner_active(tri, 2);
  }
  return false;
}

// Per-thread scratch of assign_history_slots (no allocation per particle).
std::vector<int>& scratch_slots() {
  thread_local std::vector<int> slots;
  return slots;
}

// The contact of the sphere (x, r) with candidate `ref` (r2 = r^2), appended to `out` when
// there is one.
inline void add_mesh_contact(const Vec3& x, double r, double r2, const TriRef& ref,
                             const std::vector<const TriMesh*>& meshes,
                             std::vector<MeshContact>& out) {
  const TriMesh& mesh = *meshes[ref.mesh];
  // Every point of the triangle is at least as far as its plane: most candidates end here.
  const TrianglePlane& plane = mesh.plane(ref.tri);
  const double s = dot(x - mesh.node(ref.tri, 0), plane.n);
  if (s * s >= r2 * plane.area2) return;
  const ClosestPoint cp = mesh.contact_point(ref.tri, x);
  const Vec3 d = x - cp.point;
  const double d2 = norm2(d);
  if (d2 >= r2) return;
  if (!feature_active(mesh.topology(), ref.tri, cp.region)) return;
  MeshContact c;
  c.mesh = ref.mesh;
  c.tri = ref.tri;
  c.cp = cp;
  c.dist = std::sqrt(d2);
  if (c.dist > 1e-12 * r) {
    c.normal = (1.0 / c.dist) * d;
  } else {  // centre on the surface: fall back to the facet normal
    c.normal = triangle_normal(mesh.node(c.tri, 0), mesh.node(c.tri, 1), mesh.node(c.tri, 2));
  }
  out.push_back(c);
}

}  // namespace

void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out) {
  out.clear();
  const double r2 = r * r;
  for (int k = 0; k < n; ++k) add_mesh_contact(x, r, r2, refs[k], meshes, out);
}

void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out,
                        const CandidateMotion& motion) {
  out.clear();
  const double r2 = r * r;
  // The bound, the motions and the contact distance round differently, by a few units in the
  // last place of the coordinates; a margin of 1e-6 r covers that while the coordinates stay
  // below ~1e8 radii, and costs only the skips of candidates within 1e-6 r of reach.
  const double reach = (1.0 + 1e-6) * r + motion.moved;
  for (int k = 0; k < n; ++k) {
    if (motion.dist[k] - motion.mesh_shift[refs[k].mesh] > reach) continue;
    add_mesh_contact(x, r, r2, refs[k], meshes, out);
  }
}

std::uint32_t live_slots(const double* slots) {
  std::uint32_t live = 0;
  for (int s = 0; s < kMeshSlots; ++s)
    if (slots[s * kMeshSlotWidth] != 0.0) live |= 1u << s;
  return live;
}

void release_slots(double* slots, std::uint32_t& live) {
  for (int s = 0; s < kMeshSlots; ++s)
    if (live & (1u << s)) std::fill_n(slots + s * kMeshSlotWidth, kMeshSlotWidth, 0.0);
  live = 0;
}

int assign_history_slots(double* slots, std::vector<MeshContact>& contacts,
                         const std::vector<const TriMesh*>& meshes, std::vector<double*>& history,
                         double* overflow) {
  std::uint32_t live = live_slots(slots);
  return assign_history_slots(slots, live, contacts, meshes, history, overflow);
}

int assign_history_slots(double* slots, std::uint32_t& live, std::vector<MeshContact>& contacts,
                         const std::vector<const TriMesh*>& meshes, std::vector<double*>& history,
                         double* overflow) {
  auto is_live = [&](int s) { return (live & (1u << s)) != 0; };
  // The keys as the previous step left them (step 1 writes no slot); free slots are not read.
  double keys[kMeshSlots];
  for (int s = 0; s < kMeshSlots; ++s) keys[s] = is_live(s) ? slots[s * kMeshSlotWidth] : 0.0;
  auto previous_slot = [&](double key) {
    for (int s = 0; s < kMeshSlots; ++s)
      if (keys[s] == key) return s;
    return -1;
  };
  // 1. Which contacts act, in order; persisting ones keep their slot.
  bool used[kMeshSlots] = {};
  std::vector<int>& kept_slot = scratch_slots();
  kept_slot.clear();
  std::size_t acting = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const MeshContact& mc = contacts[c];
    const int s = previous_slot(slot_key(mc));
    if (s < 0) {
      const MeshTopology& topo = meshes[mc.mesh]->topology();
      bool patch_acts = false;
      for (std::size_t a = 0; a < acting && !patch_acts; ++a)
        patch_acts = contacts[a].mesh == mc.mesh && topo.coplanar_neighbours(contacts[a].tri, mc.tri);
      if (patch_acts) continue;
    } else {
      used[s] = true;
    }
    contacts[acting++] = mc;
    kept_slot.push_back(s);
  }
  contacts.resize(acting);
  history.assign(acting, nullptr);
  // 2. New contacts: a free (or released) slot, with the history of a previous contact with a
  //    coplanar neighbour triangle if there is one.
  auto slot = [&](int s) { return slots + s * kMeshSlotWidth; };
  int overflowed = 0;
  // The live slots as the previous step left them, kept only when a new contact may copy from
  // one (the slot it copies from can be given to another new contact below).
  double before[kMeshSlots * kMeshSlotWidth];
  if (std::any_of(kept_slot.begin(), kept_slot.end(), [](int s) { return s < 0; }))
    for (int s = 0; s < kMeshSlots; ++s)
      if (is_live(s)) std::copy_n(slot(s), kMeshSlotWidth, before + s * kMeshSlotWidth);
  for (std::size_t c = 0; c < acting; ++c) {
    if (kept_slot[c] >= 0) {
      history[c] = slot(kept_slot[c]) + 1;
      continue;
    }
    const MeshContact& mc = contacts[c];
    const double* source = nullptr;
    for (int s = 0; s < kMeshSlots && !source; ++s) {
      const double key = keys[s];
      if (key == 0.0 || mesh_of_key(key) != mc.mesh) continue;
      const std::uint32_t tri = tri_of_key(key);
      if (tri != mc.tri && meshes[mc.mesh]->topology().coplanar_neighbours(tri, mc.tri))
        source = before + s * kMeshSlotWidth + 1;
    }
    // A slot not used at this step holds what the previous step left.
    int best = -1;
    for (int s = 0; s < kMeshSlots && best < 0; ++s)
      if (!used[s] && !is_live(s)) best = s;
    for (int s = 0; s < kMeshSlots && best < 0; ++s)
      if (!used[s]) best = s;
    double* h = nullptr;
    if (best < 0) {
      h = overflow + overflowed * kHistorySize;
      ++overflowed;
    } else {
      slot(best)[0] = slot_key(mc);
      h = slot(best) + 1;
      used[best] = true;
    }
    if (source) std::copy(source, source + kHistorySize, h);
    else std::fill(h, h + kHistorySize, 0.0);
    history[c] = h;
  }
  // 3. Release the slots of contacts that opened (a free slot, key 0, is all zeros already).
  std::uint32_t now = 0;
  for (int s = 0; s < kMeshSlots; ++s) {
    if (used[s]) now |= 1u << s;
    else if (is_live(s)) std::fill(slot(s), slot(s) + kMeshSlotWidth, 0.0);
  }
  live = now;
  return overflowed;
}

}  // namespace dem
