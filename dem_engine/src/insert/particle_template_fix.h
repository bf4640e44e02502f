#pragma once
#include <memory>

#include "fix/fix.h"
#include "insert/discrete_distribution.h"

namespace dem {

// `fix ID group particletemplate/sphere SEED [atom_type T] density constant RHO
//  radius constant R [volume_limit V] [relative no]`: one kind of sphere to insert.
class ParticleTemplateFix : public Fix {
 public:
  ParticleTemplateFix(Simulation& sim, const Command& command);
  const SphereTemplate& sphere() const { return sphere_; }
  double max_insert_radius() const override { return sphere_.radius; }

 private:
  SphereTemplate sphere_;
};

// `fix ID group particledistribution/discrete[/massbased|/numberbased] SEED N t1 w1 ... tN wN`:
// a discrete mixture of particle templates defined earlier in the deck.
class ParticleDistributionFix : public Fix {
 public:
  ParticleDistributionFix(Simulation& sim, const Command& command);
  const DiscreteDistribution& distribution() const { return *distribution_; }
  double max_insert_radius() const override { return distribution_->max_radius(); }

 private:
  std::unique_ptr<DiscreteDistribution> distribution_;
};

}  // namespace dem
