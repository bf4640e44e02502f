#include "mesh/fix_move_mesh.h"

#include <cmath>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {

namespace {

Vec3 vec3_at(const std::vector<std::string>& a, std::size_t pos, const std::string& what) {
  if (pos + 3 > a.size()) throw EngineError("'" + what + "' needs three values");
  return Vec3{parse_double(a[pos], what + " x"), parse_double(a[pos + 1], what + " y"),
              parse_double(a[pos + 2], what + " z")};
}

void expect_word(const std::vector<std::string>& a, std::size_t pos, const char* word,
                 const std::string& usage) {
  if (pos >= a.size() || a[pos] != word) throw EngineError("usage: " + usage);
}

double period_value(const std::string& text) {
  const double t = parse_double(text, "period");
  if (!(t > 0.0)) throw EngineError("period must be > 0, got " + text);
  return t;
}

FixMeshSurface* find_mesh_fix(Simulation& sim, const std::string& id) {
  Fix* f = sim.find_fix(id);
  if (!f) throw EngineError("move/mesh: unknown mesh fix '" + id + "'");
  auto* mesh = dynamic_cast<FixMeshSurface*>(f);
  if (!mesh) throw EngineError("move/mesh: fix '" + id + "' is not a fix mesh/surface");
  return mesh;
}

}  // namespace

FixMoveMesh::FixMoveMesh(Simulation& sim, const Command& command)
    : Fix(sim, command), t0_(sim.time) {
  const auto& a = args();
  const std::string usage =
      "fix ID group move/mesh mesh MESH_ID linear VX VY VZ | wiggle amplitude AX AY AZ period T | "
      "rotate origin PX PY PZ axis AX AY AZ period T";
  if (a.size() < 3 || a[0] != "mesh") throw EngineError("usage: " + usage);
  mesh_id_ = a[1];
  mesh_fix_ = find_mesh_fix(sim, mesh_id_);
  if (mesh_fix_->self_moving())
    throw EngineError("move/mesh: mesh " + mesh_id_ +
                      " is a servo wall, which does not allow superposition with moving mesh "
                      "fixes");
  const std::string& kind = a[2];
  Vec3 origin, axis{0, 0, 1};
  std::size_t end = 0;
  if (kind == "linear") {
    style_ = Style::kLinear;
    velocity_ = vec3_at(a, 3, "linear");
    end = 6;
  } else if (kind == "wiggle") {
    style_ = Style::kWiggle;
    expect_word(a, 3, "amplitude", usage);
    amplitude_ = vec3_at(a, 4, "amplitude");
    expect_word(a, 7, "period", usage);
    if (a.size() < 9) throw EngineError("usage: " + usage);
    omega_ = 2.0 * M_PI / period_value(a[8]);
    end = 9;
  } else if (kind == "rotate") {
    style_ = Style::kRotate;
    expect_word(a, 3, "origin", usage);
    origin = vec3_at(a, 4, "origin");
    expect_word(a, 7, "axis", usage);
    axis = vec3_at(a, 8, "axis");
    if (norm(axis) == 0.0) throw EngineError("rotation axis must be non-zero");
    axis *= 1.0 / norm(axis);
    expect_word(a, 11, "period", usage);
    if (a.size() < 13) throw EngineError("usage: " + usage);
    omega_ = 2.0 * M_PI / period_value(a[12]);
    end = 13;
  } else if (kind == "riggle" || kind == "viblin" || kind == "vibrot") {
    throw EngineError("move/mesh style '" + kind + "' is not supported by this engine");
  } else {
    throw EngineError("unknown move/mesh style '" + kind + "'; usage: " + usage);
  }
  if (a.size() > end) throw EngineError("unexpected argument '" + a[end] + "'; usage: " + usage);
  frame_ = mesh_fix_->mesh().add_frame(origin, axis);
}

FixMeshSurface& FixMoveMesh::target() { return *mesh_fix_; }

void FixMoveMesh::init() {
  // The mesh fix may have been replaced or removed since the last run.
  FixMeshSurface* now = find_mesh_fix(sim_, mesh_id_);
  if (now != mesh_fix_)
    throw EngineError("move/mesh: mesh fix '" + mesh_id_ + "' was redefined after fix " + id());
}

void FixMoveMesh::initial_integrate() {
  TriMesh& mesh = target().mesh();
  const double dt = sim_.dt;
  switch (style_) {
    case Style::kLinear:
      mesh.translate(dt * velocity_, frame_);
      break;
    case Style::kWiggle: {
      const double t_new = sim_.time - t0_, t_old = t_new - dt;
      mesh.translate((std::sin(omega_ * t_new) - std::sin(omega_ * t_old)) * amplitude_, frame_);
      break;
    }
    case Style::kRotate: {
      const TriMesh::Frame& f = mesh.frame(frame_);
      mesh.rotate(f.axis, omega_ * dt, f.origin, frame_);
      break;
    }
  }
}

// Velocities after all motions of the step, at the final node positions and frames.
void FixMoveMesh::post_integrate() { add_velocity(); }

void FixMoveMesh::add_velocity() {
  TriMesh& mesh = target().mesh();
  switch (style_) {
    case Style::kLinear:
      mesh.add_velocity(velocity_);
      break;
    case Style::kWiggle:
      mesh.add_velocity((omega_ * std::cos(omega_ * (sim_.time - t0_))) * amplitude_);
      break;
    case Style::kRotate: {
      const TriMesh::Frame& f = mesh.frame(frame_);
      mesh.add_rotation_velocity(omega_ * f.axis, f.origin);
      break;
    }
  }
}

double FixMoveMesh::max_wall_speed() const {
  switch (style_) {
    case Style::kLinear:
      return norm(velocity_);
    case Style::kWiggle:
      return omega_ * norm(amplitude_);
    case Style::kRotate: {
      const TriMesh& mesh = mesh_fix_->mesh();
      const TriMesh::Frame& f = mesh.frame(frame_);
      double r2 = 0.0;
      for (const Vec3& p : mesh.nodes()) {
        const Vec3 d = p - f.origin;
        r2 = std::max(r2, norm2(d - dot(d, f.axis) * f.axis));
      }
      return omega_ * std::sqrt(r2);
    }
  }
  return 0.0;
}

}  // namespace dem
