#pragma once
#include <string>
#include <vector>

#include "fix/fix.h"
#include "mesh/servo_controller.h"
#include "mesh/tri_mesh.h"

namespace dem {

// fix ID group mesh/surface file F type T [verbose yes|no] [scale S] [move DX DY DZ]
//     [rotate axis AX AY AZ angle DEG] [curvature DEG]
// An STL wall of material type T. scale/move/rotate are applied in the order given, about the
// origin (LIGGGHTS). Keywords come in LIGGGHTS' groups (file, pre-mesh, mesh, surface, ...);
// a keyword out of its group is an error, as in LIGGGHTS. `curvature` (0 to 60 degrees, at most
// the smallest angle of a triangle; default 0.256235) is the largest angle between the normals
// of two triangles sharing an edge for which they count as one surface: their shared edge
// makes no contact, a sphere touching both gets one contact, and its contact history moves
// from one to the other (see MeshTopology and find_mesh_contacts). The group is ignored.
class FixMeshSurface : public Fix {
 public:
  FixMeshSurface(Simulation& sim, const Command& command);

  TriMesh& mesh() { return mesh_; }
  const TriMesh& mesh() const { return mesh_; }
  int wall_type() const { return wall_type_; }

  // Force and torque the particles exert on the mesh, summed by the walls that use it.
  virtual bool tracks_stress() const { return false; }
  // Point about which the torque on the mesh is taken (m).
  virtual Vec3 reference_point() const { return Vec3{}; }
  void add_wall_load(const Vec3& force, const Vec3& torque) {
    force_ += force;
    torque_ += torque;
  }
  // A wall/gran fix marks the meshes it uses at every init.
  void mark_used_by_wall() { used_by_wall_ = true; }
  // True when a mesh/surface/stress/servo moves the mesh itself.
  virtual bool self_moving() const { return false; }

  void init() override;
  void initial_integrate() override;
  void post_integrate() override;
  double max_wall_speed() const override { return mesh_.max_node_speed(); }

 protected:
  // Index of the first argument that this class did not parse.
  std::size_t next_arg() const { return pos_; }
  void set_next_arg(std::size_t pos) { pos_ = pos; }
  // Throws for the first unparsed argument when `style()` equals `exact_style`.
  void reject_rest(const std::string& exact_style) const;

  TriMesh mesh_;
  Vec3 force_, torque_;
  bool used_by_wall_ = false;

 private:
  std::size_t pos_ = 0;
  int wall_type_ = 0;
};

// fix ID group mesh/surface/stress ... [stress on|off] [reference_point X Y Z] [wear off]
// f_ID[1..3]: force of the particles of the fix group on the mesh (N);
// f_ID[4..6]: their torque about the reference point (N m).
class FixMeshSurfaceStress : public FixMeshSurface {
 public:
  FixMeshSurfaceStress(Simulation& sim, const Command& command);
  bool tracks_stress() const override { return stress_; }
  Vec3 reference_point() const override { return reference_; }
  double vector(int index) const override;

 protected:
  Vec3 reference_;
  bool stress_ = true;
};

// fix ID group mesh/surface/stress/servo ... com X Y Z ctrlPV force axis AX AY AZ
//     target_val F vel_max V [kp KP] [ki KI] [kd KD]
// Moves the mesh along `axis` with the PID law of ServoController; target_val may be v_NAME
// (an equal-style variable read every step). f_ID[1..6] as mesh/surface/stress (torque about
// the moving com), f_ID[7..9]: the current com position (m). fix_modify ID integrate
// start|stop, target_val F|v_NAME, ctrlParam KP KI KD (also spelled servo/integrate,
// servo/target_val, servo/ctrlParam, servo/vel_max V as in the mesh-module documentation).
class FixMeshSurfaceStressServo : public FixMeshSurfaceStress {
 public:
  FixMeshSurfaceStressServo(Simulation& sim, const Command& command);
  bool self_moving() const override { return true; }
  double vector(int index) const override;
  void modify(const std::vector<std::string>& args) override;
  void init() override;
  void setup() override;
  void initial_integrate() override;
  HookWork final_integrate_work() override;
  double max_wall_speed() const override { return controller_.vel_max; }

 private:
  void set_target(const std::string& word);
  void update_speed();
  ServoController controller_;
  Vec3 com_, axis_;
  double speed_ = 0.0;  // current speed along the axis (m/s)
  std::string target_variable_;
  bool integrate_ = true;
};

}  // namespace dem
