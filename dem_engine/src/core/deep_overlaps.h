#pragma once

#include <string>

namespace dem {

// Contacts that overlap by more than half the smaller radius. LIGGGHTS 3.8 has no such check
// and carries on, so the engine does too: a deck must give the same run on both. Such overlaps
// come from a particle pinched between a moving and a fixed wall (a kinematic wall pushes with
// any force needed) or from a time step too large for the stiffness; the second also makes
// particles move more than half a radius per step, which Simulation::check_health stops.
class DeepOverlaps {
 public:
  static constexpr double kRatio = 0.5;  // overlap / smaller radius above which one is recorded

  // Records the deepest overlap of one force evaluation; true for the first of a run.
  bool record(long step, double ratio, long tag, const std::string& partner) {
    const bool first = steps_ == 0;
    if (first) first_step_ = step;
    ++steps_;
    if (ratio > worst_) {
      worst_ = ratio;
      tag_ = tag;
      partner_ = partner;
    }
    return first;
  }
  long steps() const { return steps_; }
  long first_step() const { return first_step_; }
  double worst() const { return worst_; }
  long tag() const { return tag_; }
  const std::string& partner() const { return partner_; }
  void clear() { *this = DeepOverlaps{}; }

 private:
  long steps_ = 0, first_step_ = 0, tag_ = 0;
  double worst_ = 0.0;
  std::string partner_;
};

}  // namespace dem
