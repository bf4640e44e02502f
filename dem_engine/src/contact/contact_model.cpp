#include "contact/contact_model.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "contact/cohesion_none.h"
#include "contact/cohesion_sjkr.h"
#include "contact/normal_hertz.h"
#include "contact/rolling_epsd2.h"
#include "contact/rolling_none.h"
#include "contact/tangential_history.h"
#include "core/numbers.h"
#include "core/threads.h"
#include "deck/errors.h"

namespace dem {

std::size_t parse_model_types(const std::vector<std::string>& w, std::size_t pos,
                              ModelSpec& spec) {
  // LIGGGHTS grammar: model, tangential, [cohesion], [rolling_friction], [surface] in this
  // order and at most once each.
  auto choose = [&](const char* type, std::initializer_list<const char*> names) -> std::string {
    if (pos + 1 >= w.size()) throw EngineError(std::string("missing value after '") + type + "'");
    const std::string& name = w[pos + 1];
    for (const char* n : names)
      if (name == n) {
        pos += 2;
        return name;
      }
    std::string list;
    for (const char* n : names) list += std::string(list.empty() ? "" : ", ") + n;
    throw EngineError(std::string("unsupported ") + type + " '" + name + "' (supported: " + list +
                      ")");
  };
  if (pos >= w.size() || w[pos] != "model")
    throw EngineError("expected 'model hertz tangential history ...'");
  choose("model", {"hertz"});
  if (pos >= w.size() || w[pos] != "tangential")
    throw EngineError("expected 'tangential history' after 'model hertz'");
  choose("tangential", {"history"});
  if (pos < w.size() && w[pos] == "cohesion")
    spec.cohesion_sjkr = choose("cohesion", {"sjkr", "off"}) == "sjkr";
  if (pos < w.size() && w[pos] == "rolling_friction")
    spec.rolling_epsd2 = choose("rolling_friction", {"epsd2", "off"}) == "epsd2";
  if (pos < w.size() && w[pos] == "surface") choose("surface", {"default"});
  return pos;
}

bool parse_model_keyword(const std::vector<std::string>& w, std::size_t& pos, ModelSpec& spec) {
  const std::string& key = w[pos];
  bool* flag = nullptr;
  if (key == "limitForce") flag = &spec.options.limit_force;
  else if (key == "tangential_damping") flag = &spec.options.tangential_damping;
  else if (key == "tangential_reduce" && spec.cohesion_sjkr) flag = &spec.options.tangential_reduce;
  if (!flag) return false;
  if (pos + 1 >= w.size()) throw EngineError("missing value after '" + key + "'");
  const std::string& value = w[pos + 1];
  if (value != "on" && value != "off")
    throw EngineError("'" + key + "' expects 'on' or 'off', got '" + value + "'");
  *flag = value == "on";
  pos += 2;
  return true;
}

void parse_pair_model(const std::vector<std::string>& w, std::size_t pos, ModelSpec& spec) {
  pos = parse_model_types(w, pos, spec);
  while (pos < w.size())
    if (!parse_model_keyword(w, pos, spec))
      throw EngineError("unknown argument or wrong keyword order: '" + w[pos] + "'");
}

namespace {

template <class Cohesion, class Rolling>
inline void contact_law(const ContactInput& c, const PairParams& p, const ContactStep& step,
                        double* history, ContactResult& result) {
  NormalHertz::apply(c, p, step, history, result);
  Cohesion::apply(c, p, step, history, result);
  TangentialHistory::apply(c, p, step, history, result);
  Rolling::apply(c, p, step, history, result);
}

template <class Cohesion, class Rolling>
class ComposedModel final : public ContactModel {
 public:
  using ContactModel::ContactModel;

  void evaluate(const ContactInput& c, const PairParams& p, const ContactStep& step,
                double* history, ContactResult& result) const override {
    contact_law<Cohesion, Rolling>(c, p, step, history, result);
  }

  void pair_forces(PairForceArgs& a) const override {
    const bool periodic = a.domain.periodic(0) || a.domain.periodic(1) || a.domain.periodic(2);
    if (periodic) loop<true>(a);
    else loop<false>(a);
  }

 private:
  template <bool Periodic>
  void loop(PairForceArgs& a) const {
    Particles& P = a.atoms;
    const std::size_t n = P.size();
    const int nthreads = static_cast<int>(a.thread_force.size());  // 1 for small systems
    ContactStep step;
    step.options = spec().options;
    step.dt = a.dt;
    step.update_history = a.update_history;
    double worst_ratio = 0.0;
    long worst_tag = -1;
    long contacts = 0;
    const Vec3* x = P.x.data();
    const Vec3* v = P.v.data();
    const Vec3* w = P.omega.data();
    const double* rad = P.radius.data();
    const double* mass = P.rmass.data();
    const int* type = P.type.data();
    const std::uint32_t* mask = P.mask.data();
    const std::uint32_t freeze_bit = a.freeze_bit;
    const int* first = a.list.first.data();
    const int* partner = a.list.partner.data();
    double* hist_all = a.list.history.data();
    std::uint8_t* touching = a.list.touching.data();
    const int max_pairs = a.list.max_pairs_per_particle();
    // Per thread: one past the largest particle index it adds forces to.
    std::vector<std::size_t> touched_end(static_cast<std::size_t>(nthreads), 0);
#pragma omp parallel num_threads(nthreads) reduction(+ : contacts)
    {
      // Each thread takes the pairs of its own share of particles (the list's partition, as
      // every per-particle loop does). Thread 0 adds straight into the particle arrays, the others
      // into buffers, from the start of their share up to their largest partner index, that
      // are summed in below: one thread needs neither buffers nor a reduction.
      const int tid = omp_get_thread_num();
      const int team = omp_get_num_threads();  // may be fewer than asked for
      const ParticleShare own = a.list.partition().share(n, tid, team);
      std::size_t end_j = own.end;
      for (std::size_t i = own.begin; i < own.end; ++i)
        if (first[i + 1] > first[i])
          end_j = std::max(end_j, static_cast<std::size_t>(partner[first[i + 1] - 1]) + 1);
      touched_end[static_cast<std::size_t>(tid)] = end_j;
      Vec3* f = tid == 0 ? P.f.data() : a.thread_force[tid].data();
      Vec3* t = tid == 0 ? P.torque.data() : a.thread_torque[tid].data();
      std::fill(P.f.data() + own.begin, P.f.data() + own.end, Vec3{});
      std::fill(P.torque.data() + own.begin, P.torque.data() + own.end, Vec3{});
      if (tid != 0) {
        std::fill(f + own.begin, f + end_j, Vec3{});
        std::fill(t + own.begin, t + end_j, Vec3{});
      }
      std::vector<int> hits(static_cast<std::size_t>(max_pairs));
      std::vector<ContactInput> inputs(static_cast<std::size_t>(max_pairs));
      double my_ratio = 0.0;
      long my_tag = -1;
#pragma omp barrier
      for (std::size_t i = own.begin; i < own.end; ++i) {
        const int k_end = first[i + 1];
        if (first[i] == k_end) continue;
        const Vec3 xi = x[i];
        const double ri = rad[i];
        // Pass 1 sorts the listed pairs into touching ones, without branching on a
        // coin-flip condition, and flags contacts that opened. As in LIGGGHTS, the history of
        // a pair that opened is kept while the pair stays in the list (a contact that closes
        // again before the next neighbour build resumes it); the build drops it unless the
        // pair touches at the build's positions (see NeighborList::build).
        int m = 0;
        for (int k = first[i]; k < k_end; ++k) {
          const int j = partner[k];
          Vec3 d = xi - x[j];
          if constexpr (Periodic) d = a.domain.minimum_image(d);
          const double radsum = ri + rad[j];
          const bool apart = norm2(d) >= radsum * radsum;
          hits[m] = k;
          m += !apart;
          if (apart && touching[k]) touching[k] = 0;
        }
        if (m == 0) continue;
        contacts += m;
        // Pass 2 sets up the geometry of all contacts of i before pass 3 runs their laws:
        // the square roots and divisions of different contacts then overlap in the pipeline.
        const Vec3 vi = v[i], wi = w[i];
        const double mi = mass[i];
        for (int h = 0; h < m; ++h) {
          const int j = partner[hits[h]];
          Vec3 d = xi - x[j];
          if constexpr (Periodic) d = a.domain.minimum_image(d);
          const double r = std::sqrt(norm2(d));
          const double rj = rad[j];
          const double radsum = ri + rj;
          ContactInput& c = inputs[h];
          c.dist = r;
          c.n = (1.0 / r) * d;
          c.overlap = radsum - r;
          c.ri = ri;
          c.rj = rj;
          c.r_eff = ri * rj / radsum;
          c.m_eff = mi * mass[j] / (mi + mass[j]);
          if (freeze_bit) {  // rare: branch only then
            if (mask[i] & freeze_bit) c.m_eff = mass[j];
            if (mask[j] & freeze_bit) c.m_eff = mi;
          }
          c.cri = ri - 0.5 * c.overlap;
          c.crj = rj - 0.5 * c.overlap;
          c.v_rel = vi - v[j];
          c.omega_i = wi;
          c.omega_j = w[j];
        }
        // Pass 3: the contact laws. Partners have j > i, so the sums on i stay in registers.
        Vec3 fi = f[i], ti = t[i];
        const int type_i = type[i];
        for (int h = 0; h < m; ++h) {
          const int k = hits[h];
          const int j = partner[k];
          const ContactInput& c = inputs[h];
          touching[k] = 1;
          ContactResult res;
          contact_law<Cohesion, Rolling>(c, a.material.get(type_i, type[j]), step,
                                         hist_all + static_cast<std::size_t>(k) * kHistorySize,
                                         res);
          fi += res.force;
          f[j] -= res.force;
          ti += res.torque_i;
          t[j] += res.torque_j;
          const double rmin = std::min(c.ri, c.rj);
          if (c.overlap > my_ratio * rmin) {
            my_ratio = c.overlap / rmin;
            my_tag = P.tag[i];
          }
        }
        f[i] = fi;
        t[i] = ti;
      }
#pragma omp critical
      if (my_ratio > worst_ratio) {
        worst_ratio = my_ratio;
        worst_tag = my_tag;
      }
      // Fixed-order reduction: the sum over threads does not depend on scheduling.
      if (team > 1) {
#pragma omp barrier
        for (std::size_t i = own.begin; i < own.end; ++i) {
          Vec3 fs, ts;
          // Shares are ordered: only threads up to this one start at or before i.
          for (int th = 1; th <= tid; ++th) {
            if (i >= touched_end[static_cast<std::size_t>(th)]) continue;
            fs += a.thread_force[th][i];
            ts += a.thread_torque[th][i];
          }
          P.f[i] += fs;
          P.torque[i] += ts;
        }
      }
    }
    a.max_overlap_ratio = worst_ratio;
    a.max_overlap_tag = worst_tag;
    a.contacts = contacts;
  }
};

}  // namespace

std::unique_ptr<ContactModel> make_contact_model(const ModelSpec& spec) {
  if (spec.cohesion_sjkr && spec.rolling_epsd2)
    return std::make_unique<ComposedModel<CohesionSjkr, RollingEpsd2>>(spec);
  if (spec.cohesion_sjkr) return std::make_unique<ComposedModel<CohesionSjkr, RollingNone>>(spec);
  if (spec.rolling_epsd2) return std::make_unique<ComposedModel<CohesionNone, RollingEpsd2>>(spec);
  return std::make_unique<ComposedModel<CohesionNone, RollingNone>>(spec);
}

}  // namespace dem
