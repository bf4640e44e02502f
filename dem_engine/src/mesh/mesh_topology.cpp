#include "mesh/mesh_topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "mesh/triangle_geometry.h"

namespace dem {

namespace {

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Node ids: nodes closer than kMeshNodePrecision get the id of the first of them.
std::vector<std::size_t> node_ids(const std::vector<Vec3>& nodes) {
  const std::size_t n = nodes.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return nodes[a].x < nodes[b].x; });
  UnionFind uf(n);
  const double p2 = kMeshNodePrecision * kMeshNodePrecision;
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = k + 1; l < n; ++l) {
      if (nodes[order[l]].x - nodes[order[k]].x > kMeshNodePrecision) break;
      if (norm2(nodes[order[l]] - nodes[order[k]]) <= p2) uf.join(order[k], order[l]);
    }
  std::vector<std::size_t> id(n);
  for (std::size_t k = 0; k < n; ++k) id[k] = uf.find(k);
  return id;
}

}  // namespace

MeshTopology::MeshTopology(const std::vector<Vec3>& nodes, double cos_curvature) {
  const std::size_t ntri = nodes.size() / 3;
  const std::vector<std::size_t> id = node_ids(nodes);
  flags_.assign(ntri, 0x3f);
  std::vector<Vec3> normal(ntri);
  tolerance_.assign(ntri, 0.0);
  for (std::size_t t = 0; t < ntri; ++t) {
    const Vec3 &a = nodes[3 * t], &b = nodes[3 * t + 1], &c = nodes[3 * t + 2];
    normal[t] = triangle_normal(a, b, c);
    const Vec3 centroid = (1.0 / 3.0) * (a + b + c);
    const double r_bound = std::sqrt(
        std::max({norm2(a - centroid), norm2(b - centroid), norm2(c - centroid)}));
    tolerance_[t] = kMeshNodePrecision / (2.0 * r_bound);
  }
  auto coplanar = [&](std::size_t a, std::size_t b) {
    return std::fabs(dot(normal[a], normal[b])) > cos_curvature;
  };

  // Shared edges, grouped by their two node ids; pairs taken in triangle order.
  struct EdgeUse {
    std::size_t lo, hi, tri;
    int k;
  };
  std::vector<EdgeUse> edges;
  edges.reserve(3 * ntri);
  for (std::size_t t = 0; t < ntri; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::size_t a = id[3 * t + k], b = id[3 * t + (k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), t, k});
    }
  std::sort(edges.begin(), edges.end(), [](const EdgeUse& u, const EdgeUse& v) {
    return u.lo != v.lo ? u.lo < v.lo : (u.hi != v.hi ? u.hi < v.hi : u.tri < v.tri);
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;  // coplanar neighbours, both ways
  for (std::size_t g = 0; g < edges.size();) {
    std::size_t end = g + 1;
    while (end < edges.size() && edges[end].lo == edges[g].lo && edges[end].hi == edges[g].hi)
      ++end;
    for (std::size_t u = g; u < end; ++u)
      for (std::size_t v = u + 1; v < end; ++v) {
        const EdgeUse& a = edges[u];
        const EdgeUse& b = edges[v];
        if (a.tri == b.tri) continue;
        if (coplanar(a.tri, b.tri)) {
          flags_[a.tri] &= static_cast<std::uint8_t>(~(1u << a.k));
          flags_[b.tri] &= static_cast<std::uint8_t>(~(1u << b.k));
          pairs.emplace_back(static_cast<std::uint32_t>(a.tri), static_cast<std::uint32_t>(b.tri));
          pairs.emplace_back(static_cast<std::uint32_t>(b.tri), static_cast<std::uint32_t>(a.tri));
        } else {
          flags_[a.tri] &= static_cast<std::uint8_t>(~(1u << a.k));  // a.tri < b.tri
        }
      }
    g = end;
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  neighbour_first_.assign(ntri + 1, 0);
  for (const auto& p : pairs) ++neighbour_first_[p.first + 1];
  for (std::size_t t = 0; t < ntri; ++t) neighbour_first_[t + 1] += neighbour_first_[t];
  coplanar_.resize(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) coplanar_[k] = pairs[k].second;

  // Corners: per node, the triangles containing it, grouped by shared edges through it.
  struct CornerUse {
    std::size_t node, tri;
    int k;
  };
  std::vector<CornerUse> corners;
  corners.reserve(3 * ntri);
  for (std::size_t t = 0; t < ntri; ++t)
    for (int k = 0; k < 3; ++k) corners.push_back({id[3 * t + k], t, k});
  std::sort(corners.begin(), corners.end(), [](const CornerUse& u, const CornerUse& v) {
    return u.node != v.node ? u.node < v.node : u.tri < v.tri;
  });
  for (std::size_t g = 0; g < corners.size();) {
    std::size_t end = g + 1;
    while (end < corners.size() && corners[end].node == corners[g].node) ++end;
    const std::size_t m = end - g;
    if (m > 1) {
      UnionFind uf(m);
      for (std::size_t u = 0; u < m; ++u)
        for (std::size_t v = u + 1; v < m; ++v) {
          const CornerUse& a = corners[g + u];
          const CornerUse& b = corners[g + v];
          // An edge through the node: another node common to both triangles.
          bool share = false;
          for (int i = 1; i < 3 && !share; ++i)
            for (int j = 1; j < 3 && !share; ++j)
              share = id[3 * a.tri + (a.k + i) % 3] == id[3 * b.tri + (b.k + j) % 3];
          if (share) uf.join(u, v);
        }
      // Highest triangle index of each group keeps the corner (corners are sorted by triangle).
      std::vector<char> owner_seen(m, 0);
      for (std::size_t u = m; u-- > 0;) {
        const std::size_t root = uf.find(u);
        const CornerUse& c = corners[g + u];
        if (owner_seen[root]) flags_[c.tri] &= static_cast<std::uint8_t>(~(1u << (3 + c.k)));
        owner_seen[root] = 1;
      }
    }
    g = end;
  }
}

bool MeshTopology::coplanar_neighbours(std::size_t a, std::size_t b) const {
  if (a + 1 >= neighbour_first_.size()) return false;
  const auto first = coplanar_.begin() + neighbour_first_[a];
  const auto last = coplanar_.begin() + neighbour_first_[a + 1];
  return std::binary_search(first, last, static_cast<std::uint32_t>(b));
}

}  // namespace dem
