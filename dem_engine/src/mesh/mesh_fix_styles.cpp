// Fix styles of walls and meshes.
#include <memory>

#include "fix/fix.h"
#include "mesh/fix_mesh_surface.h"
#include "mesh/fix_move_mesh.h"
#include "mesh/fix_wall_gran.h"

namespace dem {

namespace {
template <class T>
FixFactory factory() {
  return [](Simulation& sim, const Command& command) -> std::unique_ptr<Fix> {
    return std::make_unique<T>(sim, command);
  };
}
}  // namespace

void register_mesh_fix_styles(FixRegistry& registry) {
  registry["wall/gran"] = factory<FixWallGran>();
  registry["mesh/surface"] = factory<FixMeshSurface>();
  registry["mesh/surface/stress"] = factory<FixMeshSurfaceStress>();
  registry["mesh/surface/stress/servo"] = factory<FixMeshSurfaceStressServo>();
  registry["move/mesh"] = factory<FixMoveMesh>();
}

}  // namespace dem
