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
  double cri = 0.0, crj = 0.0;  // contact radii: lever arms of the tangential force (m)
  Vec3 v_rel;            // v_i - v_j at the centres (wall: v_i - v_wall at the contact point)
  Vec3 omega_i, omega_j;  // angular velocities (omega_j = 0 for a wall)
  bool wall = false;
};

// Options of the contact law (LIGGGHTS keywords after the model list).
struct ContactOptions {
  bool limit_force = false;         // limitForce on: normal force never attractive
  bool tangential_damping = true;   // tangential_damping on|off
  bool tangential_reduce = false;   // cohesion sjkr tangential_reduce on|off
};

// What one force evaluation does besides computing forces.
struct ContactStep {
  ContactOptions options;
  double dt = 0.0;
  // False while a run is set up: the forces at step 0 of a run are computed from the stored
  // history, which is left unchanged (LIGGGHTS: only the steps that move particles advance,
  // cap or store it).
  bool update_history = true;
};

// State handed from one sub-model to the next, and the result of one contact: force on i
// (the force on j is its negative) and torques.
struct ContactResult {
  double fn = 0.0;        // normal force magnitude along n, repulsive > 0 (after cohesion)
  double fn_limit = 0.0;  // the normal force that bounds friction and rolling resistance
  double kn = 0.0, kt = 0.0;  // current normal and tangential stiffness (N/m)
  double gamma_t = 0.0;   // tangential damping coefficient (kg/s), 0 with tangential_damping off
  Vec3 force;             // total force on i (N)
  Vec3 torque_i, torque_j;  // torques (N m)
};

// Contact history per contact: tangential spring displacement (3) and rolling torque (3).
constexpr int kHistorySize = 6;
constexpr int kTangentialHistory = 0;  // offset of the tangential spring
constexpr int kRollingHistory = 3;     // offset of the rolling torque

// Every sub-model (normal, cohesion, tangential, rolling; one per file) has this shape and is
// applied in that order:
//   static void apply(const ContactInput&, const PairParams&, const ContactStep&,
//                     double* history, ContactResult&);
// `history` holds the kHistorySize doubles of the contact; each sub-model uses its own part.

}  // namespace dem
