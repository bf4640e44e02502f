#pragma once
#include "core/simd.h"
#include "core/vec3.h"

namespace dem {

// The contact types and sub-models are written for a number type R: double (one contact), or
// Pack2 / Pack4 (two or four contacts in lockstep, core/simd.h), which round lane by lane
// exactly as double.

// Per type-pair material parameters, mixed once at set-up (PHYSICS.md section 3).
template <class R>
struct PairParamsT {
  R y_star = 0.0;      // effective Young's modulus Y* (Pa)
  R g_star = 0.0;      // effective shear modulus G* (Pa)
  R beta = 0.0;        // damping ratio from restitution, ln(e)/sqrt(ln(e)^2+pi^2) (<= 0)
  R mu_s = 0.0;        // sliding friction coefficient
  R mu_r = 0.0;        // rolling friction coefficient
  R cohesion = 0.0;    // SJKR cohesion energy density (J/m^3)
};
using PairParams = PairParamsT<double>;

// Geometry and kinematics of one contact, normal n pointing from j (or the wall) to i.
template <class R>
struct ContactInputT {
  Vec3Of<R> n;      // unit normal
  R overlap = 0.0;  // dn > 0 (m)
  R dist = 0.0;     // centre distance r, or centre-wall distance d for walls (m)
  R r_eff = 0.0;    // R* (m)
  R m_eff = 0.0;    // m* (kg)
  R ri = 0.0, rj = 0.0;  // radii; rj = 0 for a wall
  R cri = 0.0, crj = 0.0;  // contact radii: lever arms of the tangential force (m)
  Vec3Of<R> v_rel;  // v_i - v_j at the centres (wall: v_i - v_wall at the contact point)
  Vec3Of<R> omega_i, omega_j;  // angular velocities (omega_j = 0 for a wall)
  bool wall = false;  // the same for every lane
};
using ContactInput = ContactInputT<double>;

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
template <class R>
struct ContactResultT {
  R fn = 0.0;        // normal force magnitude along n, repulsive > 0 (after cohesion)
  R fn_limit = 0.0;  // the normal force that bounds friction and rolling resistance
  R kn = 0.0, kt = 0.0;  // current normal and tangential stiffness (N/m)
  R gamma_t = 0.0;   // tangential damping coefficient (kg/s), 0 with tangential_damping off
  Vec3Of<R> force;   // total force on i (N)
  Vec3Of<R> torque_i, torque_j;  // torques (N m)
};
using ContactResult = ContactResultT<double>;

// Contact history per contact: tangential spring displacement (3) and rolling torque (3).
constexpr int kHistorySize = 6;
constexpr int kTangentialHistory = 0;  // offset of the tangential spring
constexpr int kRollingHistory = 3;     // offset of the rolling torque

// Every sub-model (normal, cohesion, tangential, rolling; one per file) has this shape and is
// applied in that order:
//   template <class R>
//   static void apply(const ContactInputT<R>&, const PairParamsT<R>&, const ContactStep&,
//                     R* history, ContactResultT<R>&);
// `history` holds the kHistorySize values of the contact; each sub-model uses its own part.
// Conditions on R go through select() and any() (core/simd.h): each lane then takes exactly
// the branch the scalar code would.

}  // namespace dem
