#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "deck/command.h"

namespace dem {

class Simulation;

// What a fix does in post_force or final_integrate. `share` is its work on one thread's share
// of the particles, [begin, end), and may touch, per particle, only that particle (its force,
// torque, velocity, position and per-particle storage): consecutive hooks with a share, of any
// fixes, run in one parallel region with no barrier between them (each barrier costs the
// imbalance of the loop before it). `before` runs once before those shares and must not depend
// on the shares of the hooks before it; `after` runs once after all of them. A hook without a
// share runs `before`, then `after`, once every earlier hook has finished. Empty: nothing.
struct HookWork {
  std::function<void()> before;
  std::function<void(std::size_t, std::size_t)> share;
  std::function<void()> after;
};

// A LIGGGHTS fix: `fix ID GROUP STYLE args...`. The hooks run in this order every step:
// initial_integrate, post_integrate, [pre_exchange + neighbour rebuild when needed],
// (pair forces), post_force, final_integrate, end_of_step.
class Fix {
 public:
  // Parses ID, group and style from the command; args() are the words after the style.
  Fix(Simulation& sim, const Command& command);
  virtual ~Fix() = default;
  Fix(const Fix&) = delete;
  Fix& operator=(const Fix&) = delete;

  const std::string& id() const { return id_; }
  const std::string& style() const { return style_; }
  std::uint32_t group_bit() const { return group_bit_; }
  const std::vector<std::string>& args() const { return args_; }
  const SourceLocation& where() const { return where_; }

  virtual void init() {}    // start of every run, after the set-up commands
  virtual void setup() {}   // start of every run, after the step-0 forces
  virtual void initial_integrate() {}
  virtual void post_integrate() {}
  virtual void pre_exchange() {}  // insertion/deletion; call sim.particles_changed() after
  virtual HookWork post_force_work() { return {}; }
  virtual HookWork final_integrate_work() { return {}; }
  virtual void end_of_step() {}
  virtual void post_run() {}

  // f_ID (scalar) and f_ID[i] (vector, i >= 1); the defaults throw EngineError.
  virtual double scalar() const;
  virtual double vector(int index) const;
  // fix_modify ID args...; the default rejects every keyword.
  virtual void modify(const std::vector<std::string>& args);
  // Largest particle radius this fix may insert (neighbour binning before insertion).
  virtual double max_insert_radius() const { return 0.0; }
  // Largest speed of a wall this fix moves (time-step check), m/s.
  virtual double max_wall_speed() const { return 0.0; }

 protected:
  Simulation& sim_;

 private:
  std::string id_, style_;
  std::uint32_t group_bit_ = 1;
  std::vector<std::string> args_;
  SourceLocation where_;
};

using FixFactory = std::function<std::unique_ptr<Fix>(Simulation&, const Command&)>;
using FixRegistry = std::map<std::string, FixFactory>;

// Each module registers its fix styles here (see fix/fix_styles.cpp).
void register_core_fix_styles(FixRegistry& registry);
void register_mesh_fix_styles(FixRegistry& registry);
void register_insert_fix_styles(FixRegistry& registry);
void register_output_fix_styles(FixRegistry& registry);
const FixRegistry& fix_registry();

}  // namespace dem
