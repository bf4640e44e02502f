#pragma once
#include "core/vec3.h"

namespace dem {

// Per type-pair material parameters, mixed once at set-up (PHYSICS.md section 3).
struct PairParams {
  double y_star = 0.0;      // effective Young's modulus Y* (Pa)
  double g_star = 0.0;      // effective shear modulus G* (Pa)
  double beta = 0.0;        // damping ratio from restitution, ln(e)/sqrt(ln(e)^2+pi^2) (<= 0)
  double mu_s = 0.0;        // sliding friction coefficient
  double mu_r = 0.0;        // rolling friction coefficient
  double cohesion = 0.0;    // SJKR cohesion energy density (J/m^3)
};

// Geometry and kinematics of one contact, normal n pointing from j (or the wall) to i.
struct ContactInput {
  Vec3 n;                // unit normal
  double overlap = 0.0;  // dn > 0 (m)
  double dist = 0.0;     // centre distance r, or centre-wall distance d for walls (m)
  double r_eff = 0.0;    // R* (m)
  double m_eff = 0.0;    // m* (kg)
  double ri = 0.0, rj = 0.0;  // radii; rj = 0 for a wall
  double cri = 0.0, crj = 0.0;  // contact radii (lever arms)
  Vec3 v_rel;            // v_i - v_j at the centres (wall: v_i - v_wall at the contact point)
  Vec3 omega_i, omega_j;  // angular velocities (omega_j = 0 for a wall)
  bool wall = false;
};

// Result of one contact: force on i (the force on j is its negative) and torques.
struct ContactResult {
  double fn = 0.0;   // normal force magnitude along n, repulsive > 0 (after cohesion)
  double kn = 0.0, kt = 0.0;  // current normal and tangential stiffness (N/m)
  Vec3 force;        // total force on i (N)
  Vec3 torque_i, torque_j;   // torques (N m)
};

// Contact history per contact: tangential spring displacement (3) and rolling torque (3).
constexpr int kHistorySize = 6;

// Options of the normal model (LIGGGHTS keywords after the model list).
struct ContactOptions {
  bool limit_force = false;         // limitForce on: normal force never attractive
  bool tangential_damping = true;   // tangential_damping on|off
};

}  // namespace dem
