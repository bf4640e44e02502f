#pragma once
#include <optional>
#include <string>
#include <vector>

namespace dem {

// What equal-style expressions may read from the running simulation. Implemented by the
// simulation; every method throws EngineError for an unknown name, group or index.
class EvalContext {
 public:
  virtual ~EvalContext() = default;
  // Thermo keywords usable bare in expressions (step, time, dt, atoms, ke, cpu, ...);
  // std::nullopt when the name is not a thermo keyword.
  virtual std::optional<double> thermo_keyword(const std::string& name) const = 0;
  // Group functions: count(g), mass(g), xcm(g,dim), vcm(g,dim), fcm(g,dim), bound(g,xmin|...), ke(g).
  virtual double group_function(const std::string& function,
                                const std::vector<std::string>& args) const = 0;
  // c_ID (index 0) or c_ID[i] (index i >= 1); likewise f_ID and f_ID[i].
  virtual double compute_value(const std::string& id, int index) const = 0;
  virtual double fix_value(const std::string& id, int index) const = 0;
};

}  // namespace dem
