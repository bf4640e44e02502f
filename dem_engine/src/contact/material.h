#pragma once
#include <vector>

#include "contact/contact_types.h"
#include "core/properties.h"

namespace dem {

// Per type-pair contact parameters mixed once from the global properties.
class MaterialTable {
 public:
  // Throws EngineError naming the property when one is missing, has the wrong size or an
  // invalid value (as LIGGGHTS 3.8 in SI units: Y < 5e6 Pa without soft_particles yes,
  // Y > 1e9 Pa without hard_particles yes, e outside (0.05, 1], ...).
  void build(const PropertyStore& props, int ntypes, bool soft_particles, bool hard_particles,
             bool need_rolling, bool need_cohesion);
  const PairParams& get(int ti, int tj) const { return table_[(ti - 1) * n_ + (tj - 1)]; }
  int ntypes() const { return n_; }
  double youngs_modulus(int t) const { return youngs_[t - 1]; }
  double poissons_ratio(int t) const { return poisson_[t - 1]; }
  bool built() const { return n_ > 0; }

 private:
  int n_ = 0;
  std::vector<PairParams> table_;
  std::vector<double> youngs_, poisson_;
};

// beta = ln(e) / sqrt(ln(e)^2 + pi^2)
double damping_ratio(double restitution);

}  // namespace dem
