// `compute ID group pair/gran/local [keywords]`: one row per touching particle pair (walls are
// not included), with the columns of LIGGGHTS 3.8.
//
// As in LIGGGHTS 3.8, the values are those of the contact law evaluated when the compute is
// read (by a dump, at the end of a step): current positions, velocities and angular velocities,
// and the stored contact history, which is used but not advanced (the evaluation a run's set-up
// makes). It is the same law and the same pair geometry as the force loop
// (ComposedModel::loop), so at the set-up of a run the values are those integrated; after a
// step they differ from the step's forces by the damping of the velocity change of the second
// half-step.
//
// A pair that touches across a periodic boundary is, in LIGGGHTS, a particle and the ghost image
// of the other, whose velocity and angular velocity were communicated before the step's forces
// and are not updated by the second half-step: the pair's second particle has those of the
// force evaluation, in the contact law and in the `vel` columns. An internal fix, added with the
// compute, keeps a copy of them at every force evaluation of a box with periodic boundaries
// (nothing else is stored, and nothing without this compute).
#include "compute/compute_pair_gran_local.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "compute/compute_styles.h"
#include "contact/contact_model.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "fix/fix.h"

namespace dem {
namespace {

// Output blocks, written in this order whatever the order of the keywords (LIGGGHTS 3.8).
enum Block : unsigned {
  kPos = 1u << 0,              // 6: x y z of the first and of the second particle
  kVel = 1u << 1,              // 6: vx vy vz of the first and of the second particle
  kId = 1u << 2,               // 3: id1 id2 and 1 for a contact across a periodic boundary
  kForce = 1u << 3,            // 3: contact force on the first particle
  kForceNormal = 1u << 4,      // 3: its component along the line of centres
  kForceTangential = 1u << 5,  // 3: the rest
  kTorque = 1u << 6,           // 3: contact torque on the first particle (with rolling)
  kHistory = 1u << 7,          // 3 (tangential spring), 6 with rolling_friction epsd2
  kContactArea = 1u << 8,      // 1: area of the intersection circle of the two spheres
  kDelta = 1u << 9,            // 1: overlap
};

struct Keyword {
  const char* name;
  Block block;
};

constexpr Keyword kKeywords[] = {
    {"pos", kPos},
    {"vel", kVel},
    {"id", kId},
    {"force", kForce},
    {"force_normal", kForceNormal},
    {"force_tangential", kForceTangential},
    {"torque", kTorque},
    {"history", kHistory},
    {"contactArea", kContactArea},
    {"delta", kDelta},
};

// Without keywords LIGGGHTS writes all blocks except force_normal, force_tangential and delta.
constexpr unsigned kDefaultBlocks =
    kPos | kVel | kId | kForce | kTorque | kHistory | kContactArea;

// One touching pair of the neighbour list, oriented for output.
struct Contact {
  std::int64_t first_tag, second_tag;
  std::size_t i, j;  // local indices in neighbour-list order (i < j)
  std::size_t pair;  // index of the pair in the list (its history)
  bool periodic;     // the pair touches across a periodic boundary
  bool swapped;      // the output's first particle is j
};

// A position mapped into the box along periodic dimensions (LAMMPS Domain::remap): particles
// cross a periodic boundary between neighbour builds without being wrapped.
Vec3 remap(const Domain& box, Vec3 x) {
  for (int k = 0; k < 3; ++k) {
    if (!box.periodic(k)) continue;
    const double len = box.hi[k] - box.lo[k];
    while (x[k] < box.lo[k]) x[k] += len;
    while (x[k] >= box.hi[k]) x[k] -= len;
  }
  return x;
}

// The velocities and angular velocities of the particles at the last force evaluation (the
// state of LIGGGHTS' ghost particles when the compute is read), copied after the pair forces
// while the compute exists and the box has a periodic boundary.
class ForceEvaluationVelocities final : public Fix {
 public:
  static constexpr const char* kStyle = "pair/gran/local/velocities";
  ForceEvaluationVelocities(Simulation& sim, const std::string& fix_id,
                            const std::string& compute_id, const SourceLocation& where)
      : Fix(sim, fix_command(fix_id, where)), compute_id_(compute_id) {}
  HookWork post_force_work() override {
    HookWork work;
    work.before = [this] { copy(); };
    return work;
  }
  // True when the copy was taken at this step for the current particles.
  bool current() const { return step_ == sim_.step && v_.size() == sim_.atoms.size(); }
  const Vec3& v(std::size_t i) const { return v_[i]; }
  const Vec3& omega(std::size_t i) const { return omega_[i]; }

 private:
  void copy() {
    const Domain& box = sim_.domain;
    if (!(box.periodic(0) || box.periodic(1) || box.periodic(2))) return;
    const bool compute_exists =
        std::any_of(sim_.computes.begin(), sim_.computes.end(), [this](const auto& c) {
          return c->id() == compute_id_ && c->style() == "pair/gran/local";
        });
    if (!compute_exists) return;  // uncompute: nothing reads the copy any more
    v_ = sim_.atoms.v;  // copy assignment reuses the buffers
    omega_ = sim_.atoms.omega;
    step_ = sim_.step;
  }
  static Command fix_command(const std::string& fix_id, const SourceLocation& where) {
    Command command;
    command.where = where;
    command.name = "fix";
    command.args = {fix_id, "all", kStyle};
    return command;
  }
  std::string compute_id_;
  std::vector<Vec3> v_, omega_;
  long step_ = -1;
};

class ComputePairGranLocal final : public LocalCompute {
 public:
  ComputePairGranLocal(Simulation& sim, const Command& command) : LocalCompute(sim, command) {
    for (const std::string& word : args_) {
      if (word == "heatFlux")
        throw EngineError(
            "compute pair/gran/local: heatFlux needs fix heat/gran/conduction, which this "
            "engine does not have");
      const auto it = std::find_if(std::begin(kKeywords), std::end(kKeywords),
                                   [&word](const Keyword& k) { return word == k.name; });
      if (it == std::end(kKeywords))
        throw EngineError("compute pair/gran/local: unknown keyword '" + word +
                          "' (supported: pos vel id force force_normal force_tangential torque "
                          "history contactArea delta)");
      blocks_ |= it->block;  // a repeated keyword adds nothing, as in LIGGGHTS
    }
    if (args_.empty()) blocks_ = kDefaultBlocks;
    // LIGGGHTS 3.8 connects the compute to the pair style when it is defined, and refuses it
    // after the first run and a second one per pair style.
    if (!sim.pair)
      throw EngineError(
          "compute pair/gran/local needs a pair style: define pair_style gran before it");
    if (sim.step > 0)
      throw EngineError(
          "compute pair/gran/local must be defined before the first run (step 0; it is step " +
          std::to_string(sim.step) + ")");
    for (const auto& other : sim.computes)
      if (other->style() == "pair/gran/local")
        throw EngineError("only one compute pair/gran/local is allowed (compute " + other->id() +
                          " is one)");
    // Last, so that an error above leaves no fix behind; an earlier compute of this ID
    // (removed by uncompute) left its fix, which serves again.
    fix_id_ = "pair/gran/local:" + id();
    Fix* existing = sim.find_fix(fix_id_);
    if (existing && !dynamic_cast<ForceEvaluationVelocities*>(existing))
      throw EngineError("fix ID '" + fix_id_ + "' is taken; compute pair/gran/local needs it");
    if (!existing)
      sim.fixes.push_back(
          std::make_unique<ForceEvaluationVelocities>(sim, fix_id_, id(), command.where));
  }

  std::size_t local_columns() const override {
    std::size_t n = 0;
    if (blocks_ & kPos) n += 6;
    if (blocks_ & kVel) n += 6;
    if (blocks_ & kId) n += 3;
    if (blocks_ & kForce) n += 3;
    if (blocks_ & kForceNormal) n += 3;
    if (blocks_ & kForceTangential) n += 3;
    if (blocks_ & kTorque) n += 3;
    if (blocks_ & kHistory) n += history_columns();
    if (blocks_ & kContactArea) n += 1;
    if (blocks_ & kDelta) n += 1;
    return n;
  }

  LocalArray local_array() const override;

 private:
  // The history values of the pair style: the tangential spring, and the rolling torque with
  // rolling_friction epsd2 (the layout of the neighbour list's history).
  std::size_t history_columns() const {
    return sim_.pair && sim_.pair->spec().rolling_epsd2 ? 6 : 3;
  }
  std::vector<Contact> touching_pairs() const;

  unsigned blocks_ = 0;
  std::string fix_id_;  // the ForceEvaluationVelocities of this compute
};

// The touching pairs with both particles in the group, sorted by the ids of the output. Each
// pair is oriented as LIGGGHTS 3.8 lists it on one process while it has not sorted its particles
// in memory: the smaller id first, but the larger id first across a periodic boundary (LIGGGHTS
// keeps that pair from the particle with the larger id and the ghost image of the other).
std::vector<Contact> ComputePairGranLocal::touching_pairs() const {
  const Particles& p = sim_.atoms;
  const NeighborList& list = sim_.neighbor;
  const Domain& box = sim_.domain;
  const bool any_periodic = box.periodic(0) || box.periodic(1) || box.periodic(2);
  const std::uint32_t bit = group_bit();
  std::vector<Contact> contacts;
  for (std::size_t i = 0; i + 1 < list.first.size(); ++i) {
    if (!(p.mask[i] & bit)) continue;
    for (int k = list.first[i]; k < list.first[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(list.partner[static_cast<std::size_t>(k)]);
      if (!(p.mask[j] & bit)) continue;
      // The test of the force loop (pass 1).
      const Vec3 raw = p.x[i] - p.x[j];
      const Vec3 d = any_periodic ? box.minimum_image(raw) : raw;
      const double radsum = p.radius[i] + p.radius[j];
      if (norm2(d) >= radsum * radsum) continue;
      const bool periodic = d.x != raw.x || d.y != raw.y || d.z != raw.z;
      const bool swapped = periodic ? p.tag[i] < p.tag[j] : p.tag[i] > p.tag[j];
      contacts.push_back(Contact{swapped ? p.tag[j] : p.tag[i], swapped ? p.tag[i] : p.tag[j], i,
                                 j, static_cast<std::size_t>(k), periodic, swapped});
    }
  }
  std::sort(contacts.begin(), contacts.end(), [](const Contact& a, const Contact& b) {
    return a.first_tag != b.first_tag ? a.first_tag < b.first_tag : a.second_tag < b.second_tag;
  });
  return contacts;
}

LocalArray ComputePairGranLocal::local_array() const {
  LocalArray out;
  out.columns = local_columns();
  const Particles& p = sim_.atoms;
  const std::size_t n = p.size();
  if (n == 0) return out;
  const NeighborList& list = sim_.neighbor;
  if (list.first.size() != n + 1 || !sim_.material.built())
    throw EngineError("compute " + id() +
                      ": the neighbour list is not built (pair/gran/local is read during a run)");
  const ContactModel& model = sim_.pair_model();
  const Domain& box = sim_.domain;
  const bool any_periodic = box.periodic(0) || box.periodic(1) || box.periodic(2);
  const std::size_t n_history = history_columns();
  ContactStep step;
  step.options = model.spec().options;
  step.dt = sim_.dt;
  step.update_history = false;  // read, never advance, the contact history
  std::uint32_t freeze_bit = 0;  // as Simulation::compute_forces
  for (const auto& f : sim_.fixes)
    if (f->style() == "freeze") {
      freeze_bit = f->group_bit();
      break;
    }

  const std::vector<Contact> contacts = touching_pairs();
  const ForceEvaluationVelocities* at_force = nullptr;
  if (std::any_of(contacts.begin(), contacts.end(), [](const Contact& c) { return c.periodic; })) {
    at_force = dynamic_cast<const ForceEvaluationVelocities*>(sim_.find_fix(fix_id_));
    if (!at_force || !at_force->current())
      throw EngineError("compute " + id() +
                        ": the velocities of the last force evaluation are not available (was "
                        "fix " + fix_id_ + " removed?)");
  }
  out.values.reserve(contacts.size() * out.columns);
  for (const Contact& contact : contacts) {
    const std::size_t i = contact.i, j = contact.j;
    // Across a periodic boundary, the second particle of the output is LIGGGHTS' ghost.
    const bool ghost_i = contact.periodic && contact.swapped;
    const bool ghost_j = contact.periodic && !contact.swapped;
    const Vec3 vi = ghost_i ? at_force->v(i) : p.v[i];
    const Vec3 vj = ghost_j ? at_force->v(j) : p.v[j];
    const Vec3 wi = ghost_i ? at_force->omega(i) : p.omega[i];
    const Vec3 wj = ghost_j ? at_force->omega(j) : p.omega[j];
    // The contact input exactly as the force loop builds it (ComposedModel::loop, pass 2).
    Vec3 d = p.x[i] - p.x[j];
    if (any_periodic) d = box.minimum_image(d);
    const double r = std::sqrt(norm2(d));
    const double ri = p.radius[i], rj = p.radius[j];
    const double radsum = ri + rj;
    const double mi = p.rmass[i];
    ContactInput c;
    c.dist = r;
    c.n = (1.0 / r) * d;
    c.overlap = radsum - r;
    c.ri = ri;
    c.rj = rj;
    c.r_eff = ri * rj / radsum;
    c.m_eff = mi * p.rmass[j] / (mi + p.rmass[j]);
    if (freeze_bit) {
      if (p.mask[i] & freeze_bit) c.m_eff = p.rmass[j];
      if (p.mask[j] & freeze_bit) c.m_eff = mi;
    }
    c.cri = ri - 0.5 * c.overlap;
    c.crj = rj - 0.5 * c.overlap;
    c.v_rel = vi - vj;
    c.omega_i = wi;
    c.omega_j = wj;
    // A copy of the history: the evaluation must leave the simulation unchanged.
    double history[kHistorySize];
    std::copy_n(&list.history[contact.pair * kHistorySize], kHistorySize, history);
    ContactResult res;
    model.evaluate(c, sim_.material.get(p.type[i], p.type[j]), step, history, res);

    // Output oriented from the first to the second particle. The law gives the force and
    // torque on i, the torque on j, and the force -F on j; the history is oriented from i to j.
    const std::size_t a = contact.swapped ? j : i;
    const std::size_t b = contact.swapped ? i : j;
    const Vec3 force = contact.swapped ? -res.force : res.force;
    const Vec3 torque = contact.swapped ? res.torque_j : res.torque_i;
    const double history_sign = contact.swapped ? -1.0 : 1.0;
    const Vec3 first_to_second = contact.swapped ? d : -d;  // x_b - x_a (image of b)
    auto put = [&out](const Vec3& v) {
      out.values.push_back(v.x);
      out.values.push_back(v.y);
      out.values.push_back(v.z);
    };
    if (blocks_ & kPos) {
      put(remap(box, p.x[a]));
      put(remap(box, p.x[b]));
    }
    if (blocks_ & kVel) {
      put(contact.swapped ? vj : vi);
      put(contact.swapped ? vi : vj);
    }
    if (blocks_ & kId) {
      out.values.push_back(static_cast<double>(p.tag[a]));
      out.values.push_back(static_cast<double>(p.tag[b]));
      out.values.push_back(contact.periodic ? 1.0 : 0.0);
    }
    if (blocks_ & kForce) put(force);
    if (blocks_ & (kForceNormal | kForceTangential)) {
      const Vec3 normal = (1.0 / norm(first_to_second)) * first_to_second;
      const Vec3 fn = dot(force, normal) * normal;
      if (blocks_ & kForceNormal) put(fn);
      if (blocks_ & kForceTangential) put(force - fn);
    }
    if (blocks_ & kTorque) put(torque);
    if (blocks_ & kHistory)
      for (std::size_t h = 0; h < n_history; ++h) out.values.push_back(history_sign * history[h]);
    if (blocks_ & kContactArea) {
      const double rsq = norm2(d);
      out.values.push_back(-M_PI / 4.0 *
                           ((r - ri - rj) * (r + ri - rj) * (r - ri + rj) * (r + ri + rj)) / rsq);
    }
    if (blocks_ & kDelta) out.values.push_back(c.overlap);
  }
  return out;
}

}  // namespace

std::unique_ptr<Compute> make_pair_gran_local(Simulation& sim, const Command& command) {
  return std::make_unique<ComputePairGranLocal>(sim, command);
}

}  // namespace dem
