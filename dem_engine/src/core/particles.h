#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/vec3.h"

namespace dem {

// Granular particles stored per property (structure of arrays). Indices are local and change
// when particles are removed; tags (ids) are stable. Fixes that keep per-particle state register
// an extra array here so it moves with the particle when the storage is compacted.
class Particles {
 public:
  std::vector<std::int64_t> tag;
  std::vector<int> type;             // 1-based atom type
  std::vector<std::uint32_t> mask;   // group bit mask
  std::vector<Vec3> x, v, f, omega, torque;
  std::vector<double> radius, rmass, density;

  std::size_t size() const noexcept { return tag.size(); }
  // Appends a particle; mass from density and radius. Returns its local index.
  std::size_t add(std::int64_t id, int atom_type, std::uint32_t group_mask, const Vec3& position,
                  double particle_radius, double particle_density);
  // Removes the particles whose flag is non-zero, keeping the order of the others.
  void remove(const std::vector<char>& flagged);
  // Reorders the particles: new index k holds the particle that had index order[k].
  void permute(const std::vector<std::size_t>& order);
  void set_radius(std::size_t i, double r);    // keeps density, updates mass
  void set_density(std::size_t i, double rho);  // keeps radius, updates mass
  // Gives the particles the tags 1..N in the order of their current tags (delete_atoms
  // compress yes); returns (old tag, new tag) pairs sorted by the old tag.
  std::vector<std::pair<std::int64_t, std::int64_t>> renumber_tags();
  std::int64_t next_tag() noexcept { return ++max_tag_; }
  std::int64_t max_tag() const noexcept { return max_tag_; }
  // Local index of a tag, or -1.
  long index_of(std::int64_t id) const;
  // Changes whenever a particle is added, removed or reordered, or its radius or mass changes:
  // per-particle values derived from them can be cached until it does.
  std::uint64_t mass_version() const noexcept { return mass_version_; }

  // Per-particle extra storage of `width` doubles per particle, initialised to zero.
  std::size_t register_extra(const std::string& name, std::size_t width);
  std::vector<double>& extra(std::size_t handle) { return extras_[handle].data; }
  std::size_t extra_width(std::size_t handle) const { return extras_[handle].width; }

 private:
  struct Extra {
    std::string name;
    std::size_t width = 0;
    std::vector<double> data;
  };
  std::vector<Extra> extras_;
  std::int64_t max_tag_ = 0;
  std::uint64_t mass_version_ = 0;
};

double sphere_mass(double radius, double density);
// Inline: the integrator computes it for every particle twice per step.
inline double sphere_inertia(double mass, double radius) { return 0.4 * mass * radius * radius; }

}  // namespace dem
