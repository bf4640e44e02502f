#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/domain.h"
#include "core/vec3.h"

namespace dem {

// Spheres hashed into cubic cells for overlap tests during insertion. Periodic dimensions of
// the domain wrap (minimum image); other dimensions are unbounded. Memory scales with the
// number of spheres, not with the box volume.
class OverlapGrid {
 public:
  // `cell_size` > 0 (m); 2x the largest radius gives one ring of neighbour cells per query.
  OverlapGrid(const Domain& domain, double cell_size);
  void add(const Vec3& x, double radius);
  // True when a sphere at x with this radius would overlap (centre distance < sum of radii)
  // any stored sphere.
  bool overlaps(const Vec3& x, double radius) const;
  std::size_t size() const { return x_.size(); }

 private:
  std::int64_t cell_index(const Vec3& x, int dim) const;
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k);
  Domain domain_;
  double width_[3] = {0, 0, 0};
  std::int64_t ncell_[3] = {0, 0, 0};  // cells along periodic dimensions; 0 otherwise
  double max_radius_ = 0.0;
  std::vector<Vec3> x_;
  std::vector<double> r_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
  mutable std::vector<std::int64_t> range_[3];  // query scratch, reused
};

}  // namespace dem
