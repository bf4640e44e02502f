#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "insert/random_stream.h"

namespace dem {

// One particle template (fix particletemplate/sphere with constant radius and density).
struct SphereTemplate {
  std::string id;              // fix ID of the template
  int atom_type = 1;           // 1-based atom type
  double radius = 1.0;         // m
  double density = 1.0;        // kg/m^3
  std::uint32_t group_bit = 1;  // group of the template fix
  double volume() const;       // m^3
  double mass() const;         // kg
};

// Discrete mixture of sphere templates
// (fix particledistribution/discrete[/massbased|/numberbased]).
// Weights are mass fractions (mass-based) or number fractions (number-based); both are
// converted to number fractions, which is what a random draw of particles needs.
class DiscreteDistribution {
 public:
  // Throws EngineError for an empty list, a size mismatch or a weight <= 0.
  DiscreteDistribution(std::vector<SphereTemplate> templates, std::vector<double> weights,
                       bool mass_based);

  std::size_t size() const { return templates_.size(); }
  const SphereTemplate& at(std::size_t k) const { return templates_[k]; }
  // True when the given weights did not sum to 1 and were normalised.
  bool renormalised() const { return renormalised_; }
  double number_fraction(std::size_t k) const { return number_fraction_[k]; }
  double mass_fraction(std::size_t k) const { return mass_fraction_[k]; }
  double mass_expect() const { return mass_expect_; }      // mean particle mass (kg)
  double volume_expect() const { return volume_expect_; }  // mean particle volume (m^3)
  double max_radius() const { return max_radius_; }        // m

  // Splits n particles among the templates. `exact`: the counts sum to n, each template gets
  // floor(n p_k) plus at most one more, chosen by systematic sampling of the remainders so that
  // the expected count is n p_k; otherwise each count is rounded independently
  // (random_distribute uncorrelated). Returns one template index per particle, largest radius
  // first (larger particles are placed first so that dense targets can be reached).
  std::vector<std::size_t> draw(long n, RandomStream& random, bool exact) const;

 private:
  std::vector<SphereTemplate> templates_;
  std::vector<double> number_fraction_, mass_fraction_;
  std::vector<std::size_t> by_radius_;  // template indices, largest radius first
  double mass_expect_ = 0.0, volume_expect_ = 0.0, max_radius_ = 0.0;
  bool renormalised_ = false;
};

}  // namespace dem
