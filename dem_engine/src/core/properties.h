#pragma once
#include <map>
#include <string>
#include <vector>

namespace dem {

// Global material properties defined by `fix property/global NAME STYLE args`.
struct GlobalProperty {
  std::string style;           // scalar, vector, peratomtype, peratomtypepair, matrix
  int n = 0;                   // matrix size for peratomtypepair/matrix
  std::vector<double> values;  // row-major for matrices
};

class PropertyStore {
 public:
  void set(const std::string& name, GlobalProperty value, const std::string& owner_fix);
  void remove_owned_by(const std::string& owner_fix);
  bool has(const std::string& name) const { return props_.count(name) > 0; }
  const GlobalProperty& get(const std::string& name) const;  // throws EngineError naming it

 private:
  std::map<std::string, GlobalProperty> props_;
  std::map<std::string, std::string> owner_;
};

}  // namespace dem
