#include "mesh/mesh_contacts.h"

#include <algorithm>
#include <cmath>

namespace dem {

namespace {

double slot_key(const MeshContact& c) {
  // Exact in a double (below 2^53); +1 keeps 0 free for "empty".
  return static_cast<double>(c.mesh) * 4294967296.0 + static_cast<double>(c.tri) + 1.0;
}

std::uint32_t mesh_of_key(double key) {
  return static_cast<std::uint32_t>(std::floor((key - 1.0) / 4294967296.0));
}

}  // namespace

void find_mesh_contacts(const Vec3& x, double r, const TriRef* refs, int n,
                        const std::vector<const TriMesh*>& meshes, std::vector<MeshContact>& out) {
  out.clear();
  const double r2 = r * r;
  for (int k = 0; k < n; ++k) {
    const TriMesh& mesh = *meshes[refs[k].mesh];
    const ClosestPoint cp = mesh.closest_point(refs[k].tri, x);
    const Vec3 d = x - cp.point;
    const double d2 = norm2(d);
    if (d2 >= r2) continue;
    MeshContact c;
    c.mesh = refs[k].mesh;
    c.tri = refs[k].tri;
    c.cp = cp;
    c.dist = std::sqrt(d2);
    if (c.dist > 1e-12 * r) {
      c.normal = (1.0 / c.dist) * d;
    } else {  // centre on the surface: fall back to the facet normal
      c.normal = triangle_normal(mesh.node(c.tri, 0), mesh.node(c.tri, 1), mesh.node(c.tri, 2));
    }
    out.push_back(c);
  }
  if (out.size() > 1) remove_redundant_contacts(out, meshes, 1e-9 * r);
}

void remove_redundant_contacts(std::vector<MeshContact>& contacts,
                               const std::vector<const TriMesh*>& meshes, double tol) {
  const std::size_t n = contacts.size();
  // At most a handful of contacts per particle: a fixed-size mask avoids allocation.
  constexpr std::size_t kMax = 64;
  bool drop[kMax] = {};
  const std::size_t m = std::min(n, kMax);
  for (std::size_t a = 0; a < m; ++a) {
    const MeshContact& c = contacts[a];
    if (c.cp.on_face()) continue;
    for (std::size_t b = 0; b < m; ++b) {
      if (b == a) continue;
      const MeshContact& o = contacts[b];
      const bool closer = o.dist < c.dist - tol;
      const bool tie = std::fabs(o.dist - c.dist) <= tol && (o.cp.on_face() || b < a);
      if (!closer && !tie) continue;
      // Does the feature point of c lie on the other triangle?
      const ClosestPoint on_other = meshes[o.mesh]->closest_point(o.tri, c.cp.point);
      if (norm2(on_other.point - c.cp.point) <= tol * tol) {
        drop[a] = true;
        break;
      }
    }
  }
  std::size_t out = 0;
  for (std::size_t a = 0; a < n; ++a)
    if (a >= kMax || !drop[a]) contacts[out++] = contacts[a];
  contacts.resize(out);
}

int assign_history_slots(double* slots, const std::vector<MeshContact>& contacts,
                         const std::vector<double>& cos_curvature, std::vector<double*>& history,
                         double* overflow) {
  const std::size_t n = contacts.size();
  history.assign(n, nullptr);
  bool used[kMeshSlots] = {};
  auto slot = [&](int s) { return slots + s * kMeshSlotWidth; };
  // 1. Contacts that persist keep their slot.
  for (std::size_t c = 0; c < n; ++c) {
    const double key = slot_key(contacts[c]);
    for (int s = 0; s < kMeshSlots; ++s)
      if (slot(s)[0] == key) {
        history[c] = slot(s) + 4;
        used[s] = true;
        break;
      }
  }
  // 2. New contacts: inherit from a released slot of the same mesh with a similar normal,
  //    else take a free (or released) slot with a zero history.
  int overflowed = 0;
  for (std::size_t c = 0; c < n; ++c) {
    if (history[c]) continue;
    const MeshContact& mc = contacts[c];
    int best = -1;
    double best_cos = cos_curvature[mc.mesh];
    for (int s = 0; s < kMeshSlots; ++s) {
      const double* sl = slot(s);
      if (used[s] || sl[0] == 0.0 || mesh_of_key(sl[0]) != mc.mesh) continue;
      const double cs = sl[1] * mc.normal.x + sl[2] * mc.normal.y + sl[3] * mc.normal.z;
      if (cs >= best_cos) {
        best_cos = cs;
        best = s;
      }
    }
    bool fresh = false;
    if (best < 0) {
      fresh = true;
      for (int s = 0; s < kMeshSlots && best < 0; ++s)
        if (!used[s] && slot(s)[0] == 0.0) best = s;
      for (int s = 0; s < kMeshSlots && best < 0; ++s)
        if (!used[s]) best = s;
    }
    if (best < 0) {
      double* h = overflow + overflowed * kHistorySize;
      std::fill(h, h + kHistorySize, 0.0);
      history[c] = h;
      ++overflowed;
      continue;
    }
    double* sl = slot(best);
    sl[0] = slot_key(mc);
    if (fresh) std::fill(sl + 4, sl + kMeshSlotWidth, 0.0);
    history[c] = sl + 4;
    used[best] = true;
  }
  // 3. Release the slots of contacts that opened; remember the current normals.
  for (int s = 0; s < kMeshSlots; ++s)
    if (!used[s]) std::fill(slot(s), slot(s) + kMeshSlotWidth, 0.0);
  for (int s = 0; s < kMeshSlots; ++s) {
    if (!used[s]) continue;
    double* sl = slot(s);
    for (std::size_t c = 0; c < n; ++c)
      if (history[c] == sl + 4) {
        sl[1] = contacts[c].normal.x;
        sl[2] = contacts[c].normal.y;
        sl[3] = contacts[c].normal.z;
      }
  }
  return overflowed;
}

}  // namespace dem
