#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "deck/command.h"

namespace dem {

class Simulation;

// `compute ID GROUP STYLE args...`: global scalar/vector values or per-particle values.
class Compute {
 public:
  Compute(Simulation& sim, const Command& command);
  virtual ~Compute() = default;
  Compute(const Compute&) = delete;
  Compute& operator=(const Compute&) = delete;
  const std::string& id() const { return id_; }
  const std::string& style() const { return style_; }
  std::uint32_t group_bit() const { return group_bit_; }
  virtual double scalar() const;
  virtual double vector(int index) const;
  // Per-particle values (one per local particle, in local order); empty if not per-atom.
  virtual bool peratom() const { return false; }
  virtual std::vector<double> peratom_values() const { return {}; }

 protected:
  Simulation& sim_;
  std::vector<std::string> args_;

 private:
  std::string id_, style_;
  std::uint32_t group_bit_ = 1;
};

std::unique_ptr<Compute> make_compute(Simulation& sim, const Command& command);

}  // namespace dem
