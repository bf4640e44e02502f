#include "core/particles.h"

#include <algorithm>
#include <cmath>

namespace dem {

double sphere_mass(double radius, double density) {
  return 4.0 / 3.0 * M_PI * radius * radius * radius * density;
}

std::size_t Particles::add(std::int64_t id, int atom_type, std::uint32_t group_mask,
                           const Vec3& position, double particle_radius, double particle_density) {
  ++mass_version_;
  tag.push_back(id);
  type.push_back(atom_type);
  mask.push_back(group_mask);
  x.push_back(position);
  v.emplace_back();
  f.emplace_back();
  omega.emplace_back();
  torque.emplace_back();
  radius.push_back(particle_radius);
  density.push_back(particle_density);
  rmass.push_back(sphere_mass(particle_radius, particle_density));
  for (auto& e : extras_) e.data.resize(e.data.size() + e.width, 0.0);
  max_tag_ = std::max(max_tag_, id);
  return tag.size() - 1;
}

namespace {
template <class T>
void compact(std::vector<T>& values, const std::vector<char>& flagged, std::size_t width = 1) {
  std::size_t out = 0;
  const std::size_t n = flagged.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (flagged[i]) continue;
    if (out != i)
      for (std::size_t k = 0; k < width; ++k) values[out * width + k] = values[i * width + k];
    ++out;
  }
  values.resize(out * width);
}
}  // namespace

void Particles::remove(const std::vector<char>& flagged) {
  ++mass_version_;
  compact(tag, flagged);
  compact(type, flagged);
  compact(mask, flagged);
  compact(x, flagged);
  compact(v, flagged);
  compact(f, flagged);
  compact(omega, flagged);
  compact(torque, flagged);
  compact(radius, flagged);
  compact(rmass, flagged);
  compact(density, flagged);
  for (auto& e : extras_) compact(e.data, flagged, e.width);
}

namespace {
template <class T>
void reorder(std::vector<T>& values, const std::vector<std::size_t>& order, std::size_t width = 1) {
  std::vector<T> out(values.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    for (std::size_t c = 0; c < width; ++c) out[k * width + c] = values[order[k] * width + c];
  values.swap(out);
}
}  // namespace

void Particles::permute(const std::vector<std::size_t>& order) {
  ++mass_version_;
  reorder(tag, order);
  reorder(type, order);
  reorder(mask, order);
  reorder(x, order);
  reorder(v, order);
  reorder(f, order);
  reorder(omega, order);
  reorder(torque, order);
  reorder(radius, order);
  reorder(rmass, order);
  reorder(density, order);
  for (auto& e : extras_) reorder(e.data, order, e.width);
}

void Particles::set_radius(std::size_t i, double r) {
  ++mass_version_;
  radius[i] = r;
  rmass[i] = sphere_mass(r, density[i]);
}

void Particles::set_density(std::size_t i, double rho) {
  ++mass_version_;
  density[i] = rho;
  rmass[i] = sphere_mass(radius[i], rho);
}

std::vector<std::pair<std::int64_t, std::int64_t>> Particles::renumber_tags() {
  std::vector<std::size_t> order(size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tag[a] < tag[b]; });
  std::vector<std::pair<std::int64_t, std::int64_t>> map(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    map[k] = {tag[order[k]], static_cast<std::int64_t>(k + 1)};
    tag[order[k]] = static_cast<std::int64_t>(k + 1);
  }
  max_tag_ = static_cast<std::int64_t>(order.size());
  return map;
}

long Particles::index_of(std::int64_t id) const {
  for (std::size_t i = 0; i < tag.size(); ++i)
    if (tag[i] == id) return static_cast<long>(i);
  return -1;
}

std::size_t Particles::register_extra(const std::string& name, std::size_t width) {
  for (std::size_t h = 0; h < extras_.size(); ++h)
    if (extras_[h].name == name) return h;
  extras_.push_back({name, width, std::vector<double>(size() * width, 0.0)});
  return extras_.size() - 1;
}

}  // namespace dem
