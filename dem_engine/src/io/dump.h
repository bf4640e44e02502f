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

// `dump ID GROUP STYLE N FILE args...`. Written at setup and every N steps.
class Dump {
 public:
  Dump(Simulation& sim, const Command& command);
  virtual ~Dump() = default;
  Dump(const Dump&) = delete;
  Dump& operator=(const Dump&) = delete;
  const std::string& id() const { return id_; }
  long every() const { return every_; }
  virtual void write() = 0;  // current step
  virtual void modify(const std::vector<std::string>& args);  // dump_modify

 protected:
  Simulation& sim_;
  std::string file_;                // may contain '*' (replaced by the step number)
  std::vector<std::string> args_;   // words after FILE
  std::uint32_t group_bit_ = 1;
  bool first_ = false;  // dump_modify first: write at the first step of a run too
  int pad_ = 0;         // dump_modify pad: digits of the step in a '*' file name

 private:
  std::string id_, style_;
  long every_ = 1;
};

using DumpFactory = std::function<std::unique_ptr<Dump>(Simulation&, const Command&)>;
using DumpRegistry = std::map<std::string, DumpFactory>;
void register_dump_styles(DumpRegistry& registry);  // io/dump_styles.cpp
const DumpRegistry& dump_registry();

}  // namespace dem
