#include "contact/contact_model.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "contact/cohesion_none.h"
#include "contact/cohesion_sjkr.h"
#include "contact/normal_hertz.h"
#include "contact/rolling_epsd2.h"
#include "contact/rolling_none.h"
#include "contact/tangential_history.h"
#include "core/numbers.h"
#include "deck/errors.h"

namespace dem {

std::size_t parse_model_spec(const std::vector<std::string>& w, std::size_t pos, ModelSpec& spec,
                             bool allow_trailing) {
  auto expect = [&](const char* type, std::initializer_list<const char*> names) -> std::string {
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
  expect("model", {"hertz"});
  if (pos >= w.size() || w[pos] != "tangential")
    throw EngineError("expected 'tangential history' after 'model hertz'");
  expect("tangential", {"history"});
  while (pos < w.size()) {
    const std::string& key = w[pos];
    if (key == "cohesion") {
      expect("cohesion", {"sjkr", "off"});
      spec.cohesion_sjkr = w[pos - 1] == "sjkr";
    } else if (key == "rolling_friction") {
      expect("rolling_friction", {"epsd2", "off"});
      spec.rolling_epsd2 = w[pos - 1] == "epsd2";
    } else if (key == "surface") {
      expect("surface", {"default"});
    } else if (key == "limitForce" || key == "tangential_damping") {
      if (pos + 1 >= w.size()) throw EngineError("missing value after '" + key + "'");
      const bool on = parse_yes_no(w[pos + 1], key);
      if (key == "limitForce") spec.options.limit_force = on;
      else spec.options.tangential_damping = on;
      pos += 2;
    } else if (allow_trailing) {
      break;
    } else {
      throw EngineError("unknown pair_style gran keyword '" + key + "'");
    }
  }
  return pos;
}

namespace {

template <class Cohesion, class Rolling>
inline void contact_law(const ContactInput& c, const PairParams& p, const ContactOptions& opt,
                        double dt, double* history, ContactResult& result) {
  const double gamma_t = NormalHertz::apply(c, p, opt, result);
  Cohesion::apply(c, p, result);
  TangentialHistory::apply(c, p, gamma_t, dt, history, result);
  Rolling::apply(c, p, dt, history + 3, result);
}

template <class Cohesion, class Rolling>
class ComposedModel final : public ContactModel {
 public:
  using ContactModel::ContactModel;

  void evaluate(const ContactInput& c, const PairParams& p, double dt, double* history,
                ContactResult& result) const override {
    contact_law<Cohesion, Rolling>(c, p, spec().options, dt, history, result);
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
    const ContactOptions opt = spec().options;
    double worst_ratio = 0.0;
    long worst_tag = -1;
    long contacts = 0;
    const Vec3* x = P.x.data();
    const Vec3* v = P.v.data();
    const Vec3* w = P.omega.data();
    const double* rad = P.radius.data();
    const double* mass = P.rmass.data();
    const int* type = P.type.data();
    const int* first = a.list.first.data();
    const int* partner = a.list.partner.data();
    double* hist_all = a.list.history.data();
#pragma omp parallel num_threads(nthreads) reduction(+ : contacts)
    {
      // Thread 0 adds straight into the (zeroed) particle arrays; the others into buffers that
      // are summed in below: one thread needs neither buffers nor a reduction.
      const int tid = omp_get_thread_num();
      Vec3* f = tid == 0 ? P.f.data() : a.thread_force[tid].data();
      Vec3* t = tid == 0 ? P.torque.data() : a.thread_torque[tid].data();
      if (tid != 0) {
        std::fill(f, f + n, Vec3{});
        std::fill(t, t + n, Vec3{});
      }
      double my_ratio = 0.0;
      long my_tag = -1;
#pragma omp for schedule(static, 64)
      for (std::size_t i = 0; i < n; ++i) {
        for (int k = first[i]; k < first[i + 1]; ++k) {
          const int j = partner[k];
          Vec3 d = x[i] - x[j];
          if constexpr (Periodic) d = a.domain.minimum_image(d);
          const double r2 = norm2(d);
          const double radsum = rad[i] + rad[j];
          double* hist = hist_all + static_cast<std::size_t>(k) * kHistorySize;
          if (r2 >= radsum * radsum) {
            // Most listed pairs are apart and already cleared: read before writing.
            if (hist[0] != 0.0 || hist[1] != 0.0 || hist[2] != 0.0 || hist[3] != 0.0 ||
                hist[4] != 0.0 || hist[5] != 0.0)
              for (int h = 0; h < kHistorySize; ++h) hist[h] = 0.0;
            continue;
          }
          ++contacts;
          const double r = std::sqrt(r2);
          ContactInput c;
          c.dist = r;
          c.n = (1.0 / r) * d;
          c.overlap = radsum - r;
          c.ri = rad[i];
          c.rj = rad[j];
          c.r_eff = rad[i] * rad[j] / radsum;
          c.m_eff = mass[i] * mass[j] / (mass[i] + mass[j]);
          c.cri = rad[i] - 0.5 * c.overlap;
          c.crj = rad[j] - 0.5 * c.overlap;
          c.v_rel = v[i] - v[j];
          c.omega_i = w[i];
          c.omega_j = w[j];
          ContactResult res;
          contact_law<Cohesion, Rolling>(c, a.material.get(type[i], type[j]), opt, a.dt, hist,
                                         res);
          f[i] += res.force;
          f[j] -= res.force;
          t[i] += res.torque_i;
          t[j] += res.torque_j;
          const double ratio = c.overlap / std::min(rad[i], rad[j]);
          if (ratio > my_ratio) {
            my_ratio = ratio;
            my_tag = P.tag[i];
          }
        }
      }
#pragma omp critical
      if (my_ratio > worst_ratio) {
        worst_ratio = my_ratio;
        worst_tag = my_tag;
      }
      // Fixed-order reduction: the sum over threads does not depend on scheduling.
      const int team = omp_get_num_threads();  // may be fewer than asked for
      if (team > 1) {
#pragma omp for schedule(static)
        for (std::size_t i = 0; i < n; ++i) {
          Vec3 fs, ts;
          for (int th = 1; th < team; ++th) {
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
