#pragma once
#include <string>
#include <vector>

namespace dem {

class Simulation;

// Thermo output (`thermo N`, `thermo_style custom ...`, `thermo_modify ...`), printed as
// LIGGGHTS does: a header line of column names at the start of each run, then one row per
// output step, then "Loop time of ...".
class Thermo {
 public:
  long every = 0;  // 0: first and last step of a run only
  std::vector<std::string> keywords{"step", "atoms", "ke"};
  void set_style(const std::vector<std::string>& args);
  void modify(const std::vector<std::string>& args);
  void header(Simulation& sim) const;
  void row(Simulation& sim) const;
  bool lost_ignore = false;

 private:
  std::string column_name(const std::string& keyword) const;
};

}  // namespace dem
