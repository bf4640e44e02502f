#include "contact/material.h"

#include <cmath>
#include <sstream>

#include "deck/errors.h"

namespace dem {

double damping_ratio(double e) {
  const double l = std::log(e);
  return l / std::sqrt(l * l + M_PI * M_PI);
}

namespace {

std::vector<double> per_type(const PropertyStore& props, const char* name, int n) {
  const GlobalProperty& p = props.get(name);
  if (p.style != "peratomtype")
    throw EngineError(std::string(name) + " must be given as peratomtype");
  if (static_cast<int>(p.values.size()) != n) {
    std::ostringstream os;
    os << name << " has " << p.values.size() << " values but the box has " << n << " atom types";
    throw EngineError(os.str());
  }
  return p.values;
}

std::vector<double> per_pair(const PropertyStore& props, const char* name, int n) {
  const GlobalProperty& p = props.get(name);
  if (p.style != "peratomtypepair")
    throw EngineError(std::string(name) + " must be given as peratomtypepair");
  if (p.n != n || static_cast<int>(p.values.size()) != n * n) {
    std::ostringstream os;
    os << name << " is a " << p.n << "x" << p.n << " matrix but the box has " << n
       << " atom types";
    throw EngineError(os.str());
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (p.values[i * n + j] != p.values[j * n + i])
        throw EngineError(std::string(name) + " matrix is not symmetric");
  return p.values;
}

}  // namespace

void MaterialTable::build(const PropertyStore& props, int n, bool soft, bool hard,
                          bool need_rolling, bool need_cohesion) {
  youngs_ = per_type(props, "youngsModulus", n);
  poisson_ = per_type(props, "poissonsRatio", n);
  for (int t = 0; t < n; ++t) {
    if (!(youngs_[t] > 0.0)) throw EngineError("youngsModulus must be > 0");
    if (youngs_[t] < 5e6 && !soft)
      throw EngineError("youngsModulus >= 5e6 required for SI units (use command "
                        "'soft_particles yes' to override)");
    if (youngs_[t] > 1e9 && !hard)
      throw EngineError("youngsModulus <= 1e9 required for SI units (use command "
                        "'hard_particles yes' to override)");
    if (!(poisson_[t] > 0.0 && poisson_[t] <= 0.5))
      throw EngineError("poissonsRatio must be in (0, 0.5]");
  }
  const auto cor = per_pair(props, "coefficientRestitution", n);
  const auto mu = per_pair(props, "coefficientFriction", n);
  std::vector<double> mur(n * n, 0.0), ced(n * n, 0.0);
  if (need_rolling) mur = per_pair(props, "coefficientRollingFriction", n);
  if (need_cohesion) ced = per_pair(props, "cohesionEnergyDensity", n);
  table_.assign(n * n, PairParams{});
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int k = i * n + j;
      if (!(cor[k] > 0.05 && cor[k] <= 1.0))
        throw EngineError("coefficientRestitution must be in (0.05, 1]");
      if (mu[k] < 0.0) throw EngineError("coefficientFriction must be >= 0");
      if (mur[k] < 0.0) throw EngineError("coefficientRollingFriction must be >= 0");
      if (ced[k] < 0.0) throw EngineError("cohesionEnergyDensity must be >= 0");
      const double yi = youngs_[i], yj = youngs_[j], ni = poisson_[i], nj = poisson_[j];
      PairParams& p = table_[k];
      p.y_star = 1.0 / ((1.0 - ni * ni) / yi + (1.0 - nj * nj) / yj);
      p.g_star = 1.0 / (2.0 * (2.0 - ni) * (1.0 + ni) / yi + 2.0 * (2.0 - nj) * (1.0 + nj) / yj);
      p.beta = damping_ratio(cor[k]);
      p.mu_s = mu[k];
      p.mu_r = mur[k];
      p.cohesion = ced[k];
    }
  n_ = n;
}

}  // namespace dem
