#include "insert/overlap_grid.h"

#include <algorithm>
#include <cmath>

#include "deck/errors.h"

namespace dem {
namespace {
constexpr std::int64_t kOffset = std::int64_t{1} << 20;  // 21 bits per cell coordinate
}

OverlapGrid::OverlapGrid(const Domain& domain, double cell_size) : domain_(domain) {
  if (!(cell_size > 0.0)) throw EngineError("insertion grid cell size must be > 0");
  for (int d = 0; d < 3; ++d) {
    width_[d] = cell_size;
    if (domain_.periodic(d)) {
      const double length = domain_.hi[d] - domain_.lo[d];
      ncell_[d] = std::max<std::int64_t>(1, static_cast<std::int64_t>(length / cell_size));
      width_[d] = length / static_cast<double>(ncell_[d]);
    }
  }
}

std::int64_t OverlapGrid::cell_index(const Vec3& x, int dim) const {
  const double c = std::floor((x[dim] - domain_.lo[dim]) / width_[dim]);
  if (ncell_[dim] > 0) {
    auto i = static_cast<std::int64_t>(c) % ncell_[dim];
    return i < 0 ? i + ncell_[dim] : i;
  }
  // Far-away cells are clamped together; exact distances are still checked.
  return static_cast<std::int64_t>(std::clamp(c, -static_cast<double>(kOffset),
                                              static_cast<double>(kOffset - 1)));
}

std::uint64_t OverlapGrid::key(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (static_cast<std::uint64_t>(i + kOffset) << 42) |
         (static_cast<std::uint64_t>(j + kOffset) << 21) | static_cast<std::uint64_t>(k + kOffset);
}

void OverlapGrid::add(const Vec3& x, double radius) {
  const auto index = static_cast<std::uint32_t>(x_.size());
  x_.push_back(x);
  r_.push_back(radius);
  max_radius_ = std::max(max_radius_, radius);
  cells_[key(cell_index(x, 0), cell_index(x, 1), cell_index(x, 2))].push_back(index);
}

bool OverlapGrid::overlaps(const Vec3& x, double radius) const {
  if (x_.empty()) return false;
  const double reach = radius + max_radius_;
  for (int d = 0; d < 3; ++d) {
    auto& range = range_[d];
    range.clear();
    const std::int64_t centre = cell_index(x, d);
    const auto span = static_cast<std::int64_t>(std::ceil(reach / width_[d]));
    if (ncell_[d] > 0) {
      if (2 * span + 1 >= ncell_[d]) {
        for (std::int64_t i = 0; i < ncell_[d]; ++i) range.push_back(i);
      } else {
        for (std::int64_t o = -span; o <= span; ++o)
          range.push_back(((centre + o) % ncell_[d] + ncell_[d]) % ncell_[d]);
      }
    } else {
      const std::int64_t lo = std::max(centre - span, -kOffset);
      const std::int64_t hi = std::min(centre + span, kOffset - 1);
      for (std::int64_t i = lo; i <= hi; ++i) range.push_back(i);
    }
  }
  for (std::int64_t i : range_[0])
    for (std::int64_t j : range_[1])
      for (std::int64_t k : range_[2]) {
        const auto found = cells_.find(key(i, j, k));
        if (found == cells_.end()) continue;
        for (std::uint32_t s : found->second) {
          const Vec3 d = domain_.minimum_image(x - x_[s]);
          const double sum = radius + r_[s];
          if (norm2(d) < sum * sum) return true;
        }
      }
  return false;
}

}  // namespace dem
