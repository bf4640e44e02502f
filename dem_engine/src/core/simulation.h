#pragma once
#include <chrono>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "contact/material.h"
#include "core/compute.h"
#include "core/deep_overlaps.h"
#include "core/domain.h"
#include "core/groups.h"
#include "core/neighbor.h"
#include "core/particles.h"
#include "core/properties.h"
#include "core/region.h"
#include "core/thermo.h"
#include "deck/eval_context.h"
#include "deck/input.h"
#include "deck/variables.h"
#include "fix/fix.h"
#include "io/dump.h"

namespace dem {

struct EngineOptions {
  std::string log_file = "log.liggghts";  // "none" disables the log
  bool echo_screen = false;
  bool progress = true;
};

// The whole state of one simulation and the command table that changes it.
class Simulation : public CommandHandler, public EvalContext {
 public:
  explicit Simulation(EngineOptions options);
  ~Simulation() override;

  // --- state -----------------------------------------------------------------------------
  Particles atoms;
  Domain domain;
  Groups groups;
  PropertyStore properties;
  MaterialTable material;
  NeighborList neighbor;
  Variables variables;
  std::map<std::string, std::unique_ptr<Region>> regions;
  std::vector<std::unique_ptr<Fix>> fixes;
  std::vector<std::unique_ptr<Compute>> computes;
  std::vector<std::unique_ptr<Dump>> dumps;
  std::unique_ptr<ContactModel> pair;  // pair_style gran; null until defined
  Thermo thermo;

  int ntypes = 0;               // atom types from create_box
  double dt = 1e-5;             // timestep (s)
  long step = 0;                // current step
  double time = 0.0;            // simulated time (s)
  bool soft_particles = false;  // allows youngsModulus < 5e6 Pa
  bool hard_particles = false;  // allows youngsModulus > 1e9 Pa
  long run_start_step = 0, run_end_step = 0;  // of the current run

  // --- services for fixes, computes and dumps -----------------------------------------------
  Region& region(const std::string& id);                 // throws naming the id
  Fix* find_fix(const std::string& id) const;            // nullptr if absent
  Fix& fix(const std::string& id) const;                 // throws naming the id
  Compute& compute(const std::string& id) const;         // throws naming the id
  // Must be called after particles are added or removed (neighbour list, caches).
  void particles_changed();
  // Largest radius of existing particles and of particles any fix may insert.
  double max_radius() const;
  // Writes to the screen and the log file.
  void message(const std::string& text) override;
  void warning(const std::string& text);
  // A force evaluation with an overlap deeper than DeepOverlaps::kRatio of the smaller radius
  // (`partner`: "a neighbour" or "wall ID"): warned at its first occurrence in a run and
  // summed up at the run's end; the run goes on, as in LIGGGHTS.
  void note_deep_overlap(double ratio, long tag, const std::string& partner);
  std::ofstream* log_stream() { return log_.is_open() ? &log_ : nullptr; }
  Input& input() { return *input_; }
  // The step settings of a wall contact: the pair model's options, dt, and whether the
  // history advances (not while a run computes its initial forces).
  ContactStep wall_step() const;
  const ContactModel& pair_model() const;  // throws if no pair_style
  // True while a run computes its initial forces: contact histories are used, not advanced.
  bool setting_up() const { return setting_up_; }

  // --- deck interface -------------------------------------------------------------------------
  void run_deck(const std::string& path, const std::vector<std::pair<std::string,
                std::vector<std::string>>>& command_line_vars);
  void execute(const Command& command) override;
  void open_log(const std::string& path, bool append) override;
  const EvalContext& eval_context() const override { return *this; }

  // --- EvalContext ----------------------------------------------------------------------------
  std::optional<double> thermo_keyword(const std::string& name) const override;
  double group_function(const std::string& function,
                        const std::vector<std::string>& args) const override;
  double compute_value(const std::string& id, int index) const override;
  double fix_value(const std::string& id, int index) const override;

  double kinetic_energy(std::uint32_t group_bit) const;  // translational (J)
  double cpu_seconds() const;

 private:
  void run(const Command& command);
  void setup_run();
  void integrate_step();
  void compute_forces();  // pair forces, then every fix's post_force
  void pair_forces();
  // The fixes' post_force (and with final, then their final_integrate) in fix order; the shares
  // of consecutive hooks run in one parallel region (see HookWork).
  void force_hooks(bool final);
  void check_timestep();
  void check_health() const;
  void handle_lost_particles();

  EngineOptions options_;
  std::unique_ptr<Input> input_;
  std::ofstream log_;
  std::chrono::steady_clock::time_point wall_start_;
  long last_build_step_ = 0;
  PairScratch pair_scratch_;
  bool timestep_checked_ = false;
  bool setting_up_ = false;
  // `run ... pre no` skips the set-up only after an earlier run and when no particles were
  // added, removed or changed and no fix was defined or removed since (as in LIGGGHTS, the
  // forces of the last step carry over); see Simulation::run.
  bool has_run_ = false;
  bool changed_since_run_ = false;
  std::vector<const Fix*> fixes_at_run_;
  DeepOverlaps deep_overlaps_;
};

}  // namespace dem
