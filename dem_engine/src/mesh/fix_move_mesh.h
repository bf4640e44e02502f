#pragma once
#include <string>

#include "fix/fix.h"
#include "mesh/fix_mesh_surface.h"

namespace dem {

// fix ID group move/mesh mesh MESH_ID linear VX VY VZ
// fix ID group move/mesh mesh MESH_ID wiggle amplitude AX AY AZ period T
// fix ID group move/mesh mesh MESH_ID rotate origin PX PY PZ axis AX AY AZ period T
// Moves the nodes of a mesh/surface fix at every step (before the forces) and gives them the
// matching velocity. Several move/mesh fixes on one mesh superpose in the order they were
// defined; the origin and axis of a later one move with the mesh as the earlier ones move it
// (LIGGGHTS). Time is counted from the definition of the fix. The group is ignored.
class FixMoveMesh : public Fix {
 public:
  FixMoveMesh(Simulation& sim, const Command& command);
  void init() override;
  void initial_integrate() override;
  void post_integrate() override;
  double max_wall_speed() const override;

 private:
  enum class Style { kLinear, kWiggle, kRotate };
  FixMeshSurface& target();
  void add_velocity();

  std::string mesh_id_;
  FixMeshSurface* mesh_fix_ = nullptr;  // refreshed at every init (fixes may be replaced)
  std::size_t frame_ = 0;
  Style style_ = Style::kLinear;
  Vec3 velocity_;          // linear (m/s)
  Vec3 amplitude_;         // wiggle (m)
  double omega_ = 0.0;     // 2 pi / period (rad/s)
  double t0_ = 0.0;        // simulated time at definition (s)
};

}  // namespace dem
