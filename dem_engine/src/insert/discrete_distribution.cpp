#include "insert/discrete_distribution.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/particles.h"
#include "deck/errors.h"

namespace dem {

double SphereTemplate::volume() const { return 4.0 / 3.0 * M_PI * radius * radius * radius; }
double SphereTemplate::mass() const { return sphere_mass(radius, density); }

DiscreteDistribution::DiscreteDistribution(std::vector<SphereTemplate> templates,
                                           std::vector<double> weights, bool mass_based)
    : templates_(std::move(templates)) {
  if (templates_.empty()) throw EngineError("a particle distribution needs at least one template");
  if (weights.size() != templates_.size())
    throw EngineError("particle distribution has " + std::to_string(templates_.size()) +
                      " templates but " + std::to_string(weights.size()) + " weights");
  for (std::size_t k = 0; k < weights.size(); ++k)
    if (!(weights[k] > 0.0))
      throw EngineError("weight of template " + templates_[k].id + " must be > 0");
  const double sum = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (!std::isfinite(sum)) throw EngineError("the weights must sum to a finite number");
  renormalised_ = std::fabs(sum - 1.0) > 1e-10;
  for (double& w : weights) w /= sum;

  const std::size_t n = templates_.size();
  number_fraction_.resize(n);
  mass_fraction_.resize(n);
  if (mass_based) {
    // Number fraction of template k is proportional to its mass fraction over its particle mass.
    double norm = 0.0;
    for (std::size_t k = 0; k < n; ++k) norm += weights[k] / templates_[k].mass();
    for (std::size_t k = 0; k < n; ++k) {
      mass_fraction_[k] = weights[k];
      number_fraction_[k] = weights[k] / templates_[k].mass() / norm;
    }
  } else {
    double norm = 0.0;
    for (std::size_t k = 0; k < n; ++k) norm += weights[k] * templates_[k].mass();
    for (std::size_t k = 0; k < n; ++k) {
      number_fraction_[k] = weights[k];
      mass_fraction_[k] = weights[k] * templates_[k].mass() / norm;
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    mass_expect_ += number_fraction_[k] * templates_[k].mass();
    volume_expect_ += number_fraction_[k] * templates_[k].volume();
    max_radius_ = std::max(max_radius_, templates_[k].radius);
  }
  by_radius_.resize(n);
  std::iota(by_radius_.begin(), by_radius_.end(), std::size_t{0});
  std::stable_sort(by_radius_.begin(), by_radius_.end(), [this](std::size_t a, std::size_t b) {
    return templates_[a].radius > templates_[b].radius;
  });
}

std::vector<std::size_t> DiscreteDistribution::draw(long n, RandomStream& random,
                                                    bool exact) const {
  const std::size_t nt = templates_.size();
  std::vector<long> count(nt, 0);
  if (n > 0) {
    if (exact) {
      std::vector<double> remainder(nt);
      long assigned = 0;
      for (std::size_t k = 0; k < nt; ++k) {
        const double expected = static_cast<double>(n) * number_fraction_[k];
        count[k] = static_cast<long>(std::floor(expected));
        remainder[k] = expected - static_cast<double>(count[k]);
        assigned += count[k];
      }
      // Systematic sampling: pointers u, u+1, u+2, ... over the cumulative remainders select
      // template k with probability equal to its remainder (< 1, so at most once).
      const long missing = n - assigned;
      double pointer = random.uniform();
      double cumulative = 0.0;
      long placed = 0;
      for (std::size_t k = 0; k < nt && placed < missing; ++k) {
        cumulative += remainder[k];
        while (placed < missing && pointer < cumulative) {
          ++count[k];
          ++placed;
          pointer += 1.0;
        }
      }
      // Round-off can leave the last unit unplaced; give it to the largest remainder.
      if (placed < missing) {
        const auto k = static_cast<std::size_t>(
            std::max_element(remainder.begin(), remainder.end()) - remainder.begin());
        count[k] += missing - placed;
      }
    } else {
      for (std::size_t k = 0; k < nt; ++k)
        count[k] = static_cast<long>(
            std::floor(static_cast<double>(n) * number_fraction_[k] + random.uniform()));
    }
  }
  std::vector<std::size_t> order;
  for (std::size_t k : by_radius_)
    order.insert(order.end(), static_cast<std::size_t>(count[k]), k);
  // Templates of equal radius are mixed (Fisher-Yates within each run) so that a shortfall at
  // the end of a dense insertion does not fall on one of them only.
  std::size_t begin = 0;
  while (begin < order.size()) {
    std::size_t end = begin + 1;
    while (end < order.size() &&
           templates_[order[end]].radius == templates_[order[begin]].radius)
      ++end;
    for (std::size_t i = end - 1; i > begin; --i) {
      const auto j = begin + static_cast<std::size_t>(random.uniform() *
                                                      static_cast<double>(i - begin + 1));
      std::swap(order[i], order[std::min(j, i)]);
    }
    begin = end;
  }
  return order;
}

}  // namespace dem
