#include "mesh/tri_neighbor_list.h"

#include <algorithm>
#include <cmath>

namespace dem {

void TriangleNeighborList::build(const Particles& p, std::uint32_t group_bit,
                                 const std::vector<const TriMesh*>& meshes, double skin) {
  const std::size_t n = p.size();
  ++builds_;
  forced_ = false;
  skin_ = skin;
  checks_ = 0;
  x_at_build_.assign(p.x.begin(), p.x.end());
  moved2_.assign(n, 0.0);
  mesh_shift_.assign(meshes.size(), 0.0);
  tag_at_build_.assign(p.tag.begin(), p.tag.end());
  meshes_at_build_ = meshes;
  nodes_at_build_.resize(meshes.size());
  mesh_version_at_build_.resize(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    nodes_at_build_[m] = meshes[m]->nodes();
    mesh_version_at_build_[m] = meshes[m]->version();
  }
  first.assign(n + 1, 0);
  refs.clear();
  dist.clear();
  pair_particle_.clear();
  pair_ref_.clear();
  pair_dist_.clear();

  // Bounding box and largest radius of the group.
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  double rmax = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(p.mask[i] & group_bit)) continue;
    ++count;
    rmax = std::max(rmax, p.radius[i]);
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p.x[i][d]);
      hi[d] = std::max(hi[d], p.x[i][d]);
    }
  }
  if (count == 0 || meshes.empty()) return;
  const double cutoff = rmax + skin;

  // Cells at least `cutoff` wide, about one particle per cell, at most ~4 cells per particle.
  const Vec3 ext = hi - lo;
  const double volume = std::max(ext.x, cutoff) * std::max(ext.y, cutoff) * std::max(ext.z, cutoff);
  double h = std::max(cutoff, std::cbrt(volume / static_cast<double>(count)));
  int nc[3];
  auto size_grid = [&] {
    long long total = 1;
    for (int d = 0; d < 3; ++d) {
      nc[d] = std::max(1, static_cast<int>(ext[d] / h) + 1);
      total *= nc[d];
    }
    return total;
  };
  while (size_grid() > 4 * static_cast<long long>(count) + 64) h *= 1.25;
  const long long ncells = static_cast<long long>(nc[0]) * nc[1] * nc[2];
  const double inv_h = 1.0 / h;
  auto cell_coord = [&](double x, int d) {
    // Clamped as a double first: far-away triangle bounds must not overflow the int.
    const double c = std::floor((x - lo[d]) * inv_h);
    return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(nc[d] - 1)));
  };

  // Counting sort of the group particles into cells (stable: ascending index per cell).
  cell_start_.assign(static_cast<std::size_t>(ncells) + 1, 0);
  cell_items_.resize(count);
  std::vector<int>& cell_of = pair_particle_;  // reused as scratch before the pair phase
  cell_of.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(p.mask[i] & group_bit)) continue;
    const int c = (cell_coord(p.x[i].z, 2) * nc[1] + cell_coord(p.x[i].y, 1)) * nc[0] +
                  cell_coord(p.x[i].x, 0);
    cell_of[i] = c;
    ++cell_start_[c + 1];
  }
  for (long long c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  {
    std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      if (cell_of[i] >= 0) cell_items_[fill[cell_of[i]]++] = static_cast<int>(i);
  }
  pair_particle_.clear();

  const double half_diag = 0.5 * std::sqrt(3.0) * h;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriMesh& mesh = *meshes[m];
    for (std::size_t t = 0; t < mesh.size(); ++t) {
      const Vec3 &a = mesh.node(t, 0), &b = mesh.node(t, 1), &c = mesh.node(t, 2);
      int c_lo[3], c_hi[3];
      bool outside = false;
      for (int d = 0; d < 3; ++d) {
        const double tmin = std::min({a[d], b[d], c[d]}) - cutoff;
        const double tmax = std::max({a[d], b[d], c[d]}) + cutoff;
        if (tmax < lo[d] || tmin > hi[d]) outside = true;
        c_lo[d] = cell_coord(tmin, d);
        c_hi[d] = cell_coord(tmax, d);
      }
      if (outside) continue;
      // The contact point of a projection that counts as in the face (no barycentric weight
      // below -tolerance) may lie outside the triangle, by at most 4 tolerance max |node - c|
      // for any point c: its weights differ from those of a point of the triangle by at most
      // 4 tolerance in sum (twice the negative parts).
      const Vec3 centroid = (1.0 / 3.0) * (a + b + c);
      const double spread = std::sqrt(
          std::max({norm2(a - centroid), norm2(b - centroid), norm2(c - centroid)}));
      const double face_slack = 4.0 * mesh.topology().face_tolerance(t) * spread;
      const long long span = static_cast<long long>(c_hi[0] - c_lo[0] + 1) *
                             (c_hi[1] - c_lo[1] + 1) * (c_hi[2] - c_lo[2] + 1);
      // Large (e.g. tilted) triangles: skip cells whose centre is too far from the triangle.
      const bool refine = span > 8;
      for (int cz = c_lo[2]; cz <= c_hi[2]; ++cz)
        for (int cy = c_lo[1]; cy <= c_hi[1]; ++cy)
          for (int cx = c_lo[0]; cx <= c_hi[0]; ++cx) {
            const int cell = (cz * nc[1] + cy) * nc[0] + cx;
            if (cell_start_[cell] == cell_start_[cell + 1]) continue;
            if (refine) {
              const Vec3 centre{lo.x + (cx + 0.5) * h, lo.y + (cy + 0.5) * h,
                                lo.z + (cz + 0.5) * h};
              const ClosestPoint cp = closest_point_on_triangle(centre, a, b, c);
              const double reach = half_diag + cutoff;
              if (norm2(cp.point - centre) > reach * reach) continue;
            }
            for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
              const int i = cell_items_[k];
              ++checks_;
              const ClosestPoint cp = closest_point_on_triangle(p.x[i], a, b, c);
              const double reach = p.radius[i] + skin;
              const double d2 = norm2(cp.point - p.x[i]);
              if (d2 < reach * reach) {
                pair_particle_.push_back(i);
                pair_ref_.push_back({static_cast<std::uint32_t>(m), static_cast<std::uint32_t>(t)});
                pair_dist_.push_back(std::sqrt(d2) - face_slack);
              }
            }
          }
    }
  }

  // Compressed rows by particle; stable, so each row is ordered by mesh, then triangle.
  for (int i : pair_particle_) ++first[i + 1];
  for (std::size_t i = 0; i < n; ++i) first[i + 1] += first[i];
  refs.resize(pair_ref_.size());
  dist.resize(pair_ref_.size());
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (std::size_t k = 0; k < pair_ref_.size(); ++k) {
    const int slot = fill[pair_particle_[k]]++;
    refs[slot] = pair_ref_[k];
    dist[slot] = pair_dist_[k];
  }
}

bool TriangleNeighborList::due(const Particles& p, const std::vector<const TriMesh*>& meshes) {
  if (forced_ || p.size() != x_at_build_.size() || meshes != meshes_at_build_) return true;
  const double limit2 = 0.25 * skin_ * skin_;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (p.tag[i] != tag_at_build_[i]) return true;
    moved2_[i] = norm2(p.x[i] - x_at_build_[i]);
    if (moved2_[i] > limit2) return true;
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    if (meshes[m]->version() == mesh_version_at_build_[m]) continue;
    const auto& now = meshes[m]->nodes();
    const auto& then = nodes_at_build_[m];
    double most = 0.0;
    for (std::size_t k = 0; k < now.size(); ++k) most = std::max(most, norm2(now[k] - then[k]));
    if (most > limit2) return true;
    mesh_shift_[m] = std::sqrt(most);
  }
  return false;
}

}  // namespace dem

