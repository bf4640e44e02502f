#include <algorithm>
#include <limits>
#include <string>

#include "compute/compute_styles.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {
namespace {

// `compute ID group reduce sum|min|max|ave|sumsq|avesq input1 ...` with inputs x y z vx vy vz
// fx fy fz or c_ID (per-atom compute): one global value per input over the group's particles
// (scalar for one input, vector otherwise).
class ComputeReduce : public Compute {
 public:
  ComputeReduce(Simulation& sim, const Command& command) : Compute(sim, command) {
    if (args_.size() < 2)
      throw EngineError("usage: compute ID group reduce sum|min|max|ave|sumsq|avesq inputs...");
    mode_ = args_[0];
    if (mode_ != "sum" && mode_ != "min" && mode_ != "max" && mode_ != "ave" &&
        mode_ != "sumsq" && mode_ != "avesq")
      throw EngineError("compute reduce mode must be sum, min, max, ave, sumsq or avesq, got '" +
                        mode_ + "'");
    static const std::string kinds[] = {"x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz"};
    for (std::size_t k = 1; k < args_.size(); ++k) {
      const std::string& word = args_[k];
      Input in;
      if (std::find(std::begin(kinds), std::end(kinds), word) != std::end(kinds)) {
        in.component = static_cast<int>(std::find(std::begin(kinds), std::end(kinds), word) -
                                        std::begin(kinds));
      } else if (word.rfind("c_", 0) == 0 && word.size() > 2 &&
                 word.find('[') == std::string::npos) {
        in.compute_id = word.substr(2);
        if (!sim.compute(in.compute_id).peratom())
          throw EngineError("compute reduce: compute " + in.compute_id +
                            " does not compute per-atom values");
      } else {
        throw EngineError("compute reduce input '" + word +
                          "' is not supported (x y z vx vy vz fx fy fz or c_ID)");
      }
      inputs_.push_back(in);
    }
  }

  double scalar() const override {
    if (inputs_.size() != 1)
      throw EngineError("compute " + id() + " (reduce) has several inputs: use c_" + id() + "[i]");
    return reduce(inputs_[0]);
  }
  double vector(int index) const override {
    if (inputs_.size() == 1)
      throw EngineError("compute " + id() + " (reduce) has one input: use c_" + id());
    if (index < 1 || index > static_cast<int>(inputs_.size()))
      throw EngineError("compute " + id() + " (reduce) has no element " + std::to_string(index));
    return reduce(inputs_[static_cast<std::size_t>(index - 1)]);
  }

 private:
  struct Input {
    int component = -1;  // 0..8: x y z vx vy vz fx fy fz
    std::string compute_id;
  };

  double reduce(const Input& in) const {
    const Particles& p = sim_.atoms;
    std::vector<double> values;
    if (!in.compute_id.empty()) values = sim_.compute(in.compute_id).peratom_values();
    // LAMMPS starts min/max from +-1e20 so an empty group gives those values.
    double result = mode_ == "min" ? 1e20 : (mode_ == "max" ? -1e20 : 0.0);
    long count = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!(p.mask[i] & group_bit())) continue;
      double v = 0.0;
      if (in.component >= 0) {
        const Vec3& vec = in.component < 3 ? p.x[i] : (in.component < 6 ? p.v[i] : p.f[i]);
        v = vec[in.component % 3];
      } else {
        v = values.at(i);
      }
      if (mode_ == "min") result = std::min(result, v);
      else if (mode_ == "max") result = std::max(result, v);
      else if (mode_ == "sumsq" || mode_ == "avesq") result += v * v;
      else result += v;
      ++count;
    }
    if ((mode_ == "ave" || mode_ == "avesq") && count > 0) result /= static_cast<double>(count);
    return result;
  }

  std::string mode_;
  std::vector<Input> inputs_;
};

}  // namespace

std::unique_ptr<Compute> make_reduce(Simulation& sim, const Command& command) {
  return std::make_unique<ComputeReduce>(sim, command);
}

}  // namespace dem
