#include "mesh/fix_mesh_surface.h"

#include <cmath>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "mesh/stl_io.h"

namespace dem {

namespace {

constexpr double kDegree = M_PI / 180.0;

bool is_unsupported_mesh_keyword(const std::string& w) {
  return w == "precision" || w == "heal" || w == "region" || w == "min_feature_length" ||
         w == "element_exclusion_list" || w == "temperature" || w == "mass_temperature" ||
         w == "surface_vel" || w == "surface_ang_vel" || w == "curvature_tolerant" ||
         w == "extrude_planar" || w == "mode" || w == "ratio";
}

Vec3 parse_vec3(const std::vector<std::string>& a, std::size_t pos, const std::string& what) {
  if (pos + 3 > a.size()) throw EngineError("'" + what + "' needs three values");
  return Vec3{parse_double(a[pos], what + " x"), parse_double(a[pos + 1], what + " y"),
              parse_double(a[pos + 2], what + " z")};
}

}  // namespace

FixMeshSurface::FixMeshSurface(Simulation& sim, const Command& command) : Fix(sim, command) {
  const auto& a = args();
  if (a.size() < 2 || a[0] != "file")
    throw EngineError("expected 'file FILENAME' after '" + style() + "'");
  const std::string& path = a[1];
  std::size_t p = 2;
  auto need = [&](std::size_t n, const std::string& key) {
    if (p + n >= a.size()) throw EngineError("not enough values after '" + key + "'");
  };
  // Pre-mesh keywords.
  for (bool more = true; more && p < a.size();) {
    more = false;
    if (a[p] == "type") {
      need(1, "type");
      const long t = parse_int(a[p + 1], "mesh type");
      if (t < 1) throw EngineError("'type' > 0 required, got " + a[p + 1]);
      if (t > sim.ntypes)
        throw EngineError("mesh type " + a[p + 1] + " exceeds the " + std::to_string(sim.ntypes) +
                          " atom types of create_box");
      wall_type_ = static_cast<int>(t);
      p += 2;
      more = true;
    } else if (a[p] == "verbose") {
      need(1, "verbose");
      parse_yes_no(a[p + 1], "verbose");
      p += 2;
      more = true;
    }
  }
  if (wall_type_ == 0) throw EngineError("fix " + style() + " needs 'type T' (the wall material)");
  mesh_ = TriMesh(read_stl(path), "STL file '" + path + "'");
  // Mesh keywords, applied in the order given.
  for (bool more = true; more && p < a.size();) {
    more = true;
    if (a[p] == "scale") {
      need(1, "scale");
      const double s = parse_double(a[p + 1], "scale");
      if (!(s > 0.0)) throw EngineError("scale must be > 0, got " + a[p + 1]);
      mesh_.scale(s);
      p += 2;
    } else if (a[p] == "move") {
      mesh_.translate(parse_vec3(a, p + 1, "move"));
      p += 4;
    } else if (a[p] == "rotate") {
      if (p + 7 > a.size() || a[p + 1] != "axis" || a[p + 5] != "angle")
        throw EngineError("usage: rotate axis AX AY AZ angle DEG");
      const Vec3 axis = parse_vec3(a, p + 2, "rotate axis");
      if (norm(axis) < 1e-5) throw EngineError("illegal magnitude of rotation axis");
      const double angle = parse_double(a[p + 6], "rotate angle") * kDegree;
      mesh_.rotate((1.0 / norm(axis)) * axis, angle, Vec3{});
      p += 7;
    } else {
      more = false;
    }
  }
  // Surface keywords.
  double curvature_deg = kDefaultCurvatureDegrees;
  for (bool more = true; more && p < a.size();) {
    more = false;
    if (a[p] == "curvature") {
      need(1, "curvature");
      curvature_deg = parse_double(a[p + 1], "curvature");
      if (!(curvature_deg > 0.0 && curvature_deg < 60.0))
        throw EngineError("0 < curvature < 60 degrees required, got " + a[p + 1]);
      p += 2;
      more = true;
    }
  }
  // After scale, move and rotate: nodes are merged at the final size.
  mesh_.set_curvature(curvature_deg, "STL file '" + path + "'");
  pos_ = p;
  reject_rest("mesh/surface");
  sim.message("Import of mesh " + id() + " containing " + std::to_string(mesh_.size()) +
              " triangle(s) from '" + path + "' successful");
  // LIGGGHTS deletes (or wraps) elements outside the box, so such a deck behaves differently
  // there.
  Vec3 lo, hi;
  mesh_.bounding_box(lo, hi);
  const Vec3 tol = 1e-9 * (sim.domain.hi - sim.domain.lo);
  for (int d = 0; d < 3; ++d)
    if (lo[d] < sim.domain.lo[d] - tol[d] || hi[d] > sim.domain.hi[d] + tol[d]) {
      sim.warning("mesh " + id() + " extends beyond the simulation box in " +
                  std::string(1, static_cast<char>('x' + d)) +
                  "; LIGGGHTS would delete or wrap the elements outside");
      break;
    }
}

void FixMeshSurface::reject_rest(const std::string& exact_style) const {
  if (style() != exact_style || pos_ >= args().size()) return;
  const std::string& w = args()[pos_];
  if (is_unsupported_mesh_keyword(w))
    throw EngineError("keyword '" + w + "' of " + style() + " is not supported by this engine");
  throw EngineError("unknown keyword or wrong keyword order: " + w);
}

void FixMeshSurface::init() {
  // The forces at the set-up of a run see the wall at rest, as in LIGGGHTS: node velocities
  // are set again by the motions of the first step.
  mesh_.clear_velocities();
  used_by_wall_ = false;
  force_ = torque_ = Vec3{};
}

void FixMeshSurface::initial_integrate() { mesh_.clear_velocities(); }

void FixMeshSurface::post_integrate() { force_ = torque_ = Vec3{}; }

// --- mesh/surface/stress --------------------------------------------------------------------

FixMeshSurfaceStress::FixMeshSurfaceStress(Simulation& sim, const Command& command)
    : FixMeshSurface(sim, command) {
  const auto& a = args();
  std::size_t p = next_arg();
  for (bool more = true; more && p < a.size();) {
    more = true;
    if (a[p] == "reference_point") {
      reference_ = parse_vec3(a, p + 1, "reference_point");
      p += 4;
    } else if (a[p] == "stress") {
      if (p + 1 >= a.size()) throw EngineError("not enough values after 'stress'");
      if (a[p + 1] == "on") stress_ = true;
      else if (a[p + 1] == "off") stress_ = false;
      else throw EngineError("expecting 'on' or 'off' as stress argument, got '" + a[p + 1] + "'");
      p += 2;
    } else if (a[p] == "wear") {
      if (p + 1 >= a.size()) throw EngineError("not enough values after 'wear'");
      if (a[p + 1] != "off")
        throw EngineError("wear model '" + a[p + 1] + "' is not supported by this engine");
      p += 2;
    } else {
      more = false;
    }
  }
  set_next_arg(p);
  reject_rest("mesh/surface/stress");
}

double FixMeshSurfaceStress::vector(int index) const {
  if (index >= 1 && index <= 3) return force_[index - 1];
  if (index >= 4 && index <= 6) return torque_[index - 4];
  return Fix::vector(index);
}

// --- mesh/surface/stress/servo --------------------------------------------------------------

FixMeshSurfaceStressServo::FixMeshSurfaceStressServo(Simulation& sim, const Command& command)
    : FixMeshSurfaceStress(sim, command) {
  if (!stress_) throw EngineError("stress = 'on' required");
  const auto& a = args();
  std::size_t p = next_arg();
  bool have_com = false, have_ctrl = false, have_axis = false, have_target = false,
       have_vmax = false;
  auto value = [&](const std::string& key) -> const std::string& {
    if (p + 1 >= a.size()) throw EngineError("not enough arguments for '" + key + "'");
    return a[p + 1];
  };
  while (p < a.size()) {
    const std::string& key = a[p];
    if (key == "com") {
      com_ = parse_vec3(a, p + 1, "com");
      have_com = true;
      p += 4;
    } else if (key == "ctrlPV") {
      const std::string& v = value(key);
      if (v == "torque")
        throw EngineError("ctrlPV torque is not supported by this engine (only force)");
      if (v != "force") throw EngineError("only 'force', 'torque' are valid arguments for ctrlPV");
      have_ctrl = true;
      p += 2;
    } else if (key == "axis") {
      axis_ = parse_vec3(a, p + 1, "axis");
      have_axis = true;
      p += 4;
    } else if (key == "target_val") {
      set_target(value(key));
      have_target = true;
      p += 2;
    } else if (key == "vel_max") {
      controller_.vel_max = parse_double(value(key), "vel_max");
      if (!(controller_.vel_max > 0.0)) throw EngineError("vel_max > 0 required");
      have_vmax = true;
      p += 2;
    } else if (key == "kp" || key == "ki" || key == "kd") {
      const double k = parse_double(value(key), key);
      (key == "kp" ? controller_.kp : key == "ki" ? controller_.ki : controller_.kd) = k;
      p += 2;
    } else {
      set_next_arg(p);
      reject_rest(style());
    }
  }
  set_next_arg(p);
  if (!have_ctrl) throw EngineError("please define 'ctrlPV' for the mesh");
  if (!have_com) throw EngineError("please define 'com' for the mesh");
  if (!have_target) throw EngineError("please define 'target_val' for the mesh");
  if (!have_vmax) throw EngineError("please define 'vel_max' for the mesh");
  if (!have_axis || norm(axis_) == 0.0) throw EngineError("please define a non-zero 'axis'");
  axis_ *= 1.0 / norm(axis_);
  if (controller_.kp < 0.0 || controller_.ki < 0.0 || controller_.kd < 0.0)
    throw EngineError("kp, ki, and kd >= 0 required.");
  if (controller_.kp == 0.0 && controller_.ki == 0.0 && controller_.kd == 0.0)
    throw EngineError("kp, ki, and kd are zero. Please set a valid configuration");
  reference_ = com_;
}

void FixMeshSurfaceStressServo::set_target(const std::string& word) {
  if (word.rfind("v_", 0) == 0) {
    target_variable_ = word.substr(2);  // checked at init, as the variable may come later
    return;
  }
  target_variable_.clear();
  controller_.set_target(parse_double(word, "target_val"));
}

double FixMeshSurfaceStressServo::vector(int index) const {
  if (index >= 7 && index <= 9) return com_[index - 7];
  return FixMeshSurfaceStress::vector(index);
}

void FixMeshSurfaceStressServo::modify(const std::vector<std::string>& args) {
  std::size_t p = 0;
  while (p < args.size()) {
    // LIGGGHTS 3.8 spells these integrate, target_val and ctrlParam; its mesh-module
    // documentation adds the servo/ prefix (and servo/vel_max).
    std::string key = args[p];
    const bool prefixed = key.rfind("servo/", 0) == 0;
    if (prefixed) key = key.substr(6);
    auto value = [&](std::size_t k) -> const std::string& {
      if (p + k >= args.size())
        throw EngineError("fix_modify " + id() + ": not enough arguments for '" + args[p] + "'");
      return args[p + k];
    };
    if (key == "integrate") {
      const std::string& v = value(1);
      if (v == "start") integrate_ = true;
      else if (v == "stop") integrate_ = false;
      else throw EngineError("wrong argument for fix_modify 'integrate': '" + v + "'");
      p += 2;
    } else if (key == "target_val") {
      set_target(value(1));
      controller_.reset_integral();
      p += 2;
    } else if (key == "ctrlParam") {
      const double kp = parse_double(value(1), "kp"), ki = parse_double(value(2), "ki"),
                   kd = parse_double(value(3), "kd");
      if (kp < 0.0 || ki < 0.0 || kd < 0.0) throw EngineError("kp, ki, and kd >= 0 required.");
      if (kp == 0.0 && ki == 0.0 && kd == 0.0) throw EngineError("kp, ki, and kd are zero");
      controller_.kp = kp;
      controller_.ki = ki;
      controller_.kd = kd;
      controller_.reset_integral();
      p += 4;
    } else if (key == "vel_max" && prefixed) {
      const double v = parse_double(value(1), "vel_max");
      if (!(v > 0.0)) throw EngineError("vel_max > 0 required");
      controller_.vel_max = v;
      p += 2;
    } else {
      Fix::modify(std::vector<std::string>(args.begin() + p, args.end()));
    }
  }
}

void FixMeshSurfaceStressServo::init() {
  FixMeshSurface::init();
  if (controller_.vel_max >= sim_.neighbor.skin / (2.0 * sim_.dt))
    throw EngineError("vel_max < skin/(2*dt) required (vel_max " +
                      std::to_string(controller_.vel_max) + " m/s, skin/(2 dt) " +
                      std::to_string(sim_.neighbor.skin / (2.0 * sim_.dt)) + " m/s)");
  if (!target_variable_.empty()) {
    const std::string& name = target_variable_;
    if (!sim_.variables.exists(name))
      throw EngineError("target_val: variable '" + name + "' does not exist");
    if (sim_.variables.style(name) != Variables::Style::Equal)
      throw EngineError("target_val: variable '" + name + "' is not equal-style");
  }
  if (!integrate_) speed_ = 0.0;
}

void FixMeshSurfaceStressServo::setup() {
  if (!used_by_wall_)
    throw EngineError("the servo wall " + id() +
                      " requires a contact model: use it in a fix wall/gran too");
}

void FixMeshSurfaceStressServo::initial_integrate() {
  FixMeshSurface::initial_integrate();
  if (!integrate_) {
    speed_ = 0.0;
    return;
  }
  const Vec3 d = (speed_ * sim_.dt) * axis_;
  com_ += d;
  reference_ = com_;
  mesh_.translate(d);
  mesh_.add_velocity(speed_ * axis_);
}

HookWork FixMeshSurfaceStressServo::final_integrate_work() {
  HookWork work;
  work.before = [this] { update_speed(); };
  return work;
}

void FixMeshSurfaceStressServo::update_speed() {
  if (!integrate_) return;
  if (!target_variable_.empty())
    controller_.set_target(sim_.variables.number(target_variable_, sim_));
  speed_ = controller_.update(dot(force_, axis_), sim_.dt);
}

}  // namespace dem
