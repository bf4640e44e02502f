#include "contact/contact_model.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
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

// How far the pairs of one share reach past it: one past the largest partner (at least the
// share's end), and the first particle with a partner past the share (the share's end if none).
struct ShareReach {
  std::size_t end, from;
};

ShareReach reach_of(const NeighborList& list, const ParticleShare& own) {
  ShareReach reach{own.end, own.end};
  // Partners are sorted, so a particle's last one is its largest.
  for (std::size_t i = own.begin; i < own.end; ++i) {
    if (list.first[i + 1] == list.first[i]) continue;
    const auto last = static_cast<std::size_t>(list.partner[list.first[i + 1] - 1]);
    if (last >= own.end && reach.from == own.end) reach.from = i;
    reach.end = std::max(reach.end, last + 1);
  }
  return reach;
}

// A pack whose lane l is f(l).
template <class P, class F>
DEM_INLINE P lanes_of(F f) {
  if constexpr (std::is_same_v<P, Pack2>) return P(f(0), f(1));
  else if constexpr (std::is_same_v<P, Pack4>) return P(f(0), f(1), f(2), f(3));
  else {
    // Two halves joined: built lane by lane, GCC fills an 8-lane vector with one masked
    // broadcast per lane.
    const Pack4 lo(f(0), f(1), f(2), f(3)), hi(f(4), f(5), f(6), f(7));
    return P(__builtin_shufflevector(lo.v, hi.v, 0, 1, 2, 3, 4, 5, 6, 7));
  }
}

// A pack of vectors whose lane l is the vector f(l).
template <class P, class F>
DEM_INLINE Vec3T<P> vec3_lanes(F f) {
  return {lanes_of<P>([&](int l) { return f(l).x; }), lanes_of<P>([&](int l) { return f(l).y; }),
          lanes_of<P>([&](int l) { return f(l).z; })};
}

// The material parameters of the pack's contacts, lane l from q[l].
template <class P>
DEM_INLINE PairParamsT<P> pack_params(const PairParams* const* q) {
  PairParamsT<P> p;
  p.y_star = lanes_of<P>([&](int l) { return q[l]->y_star; });
  p.g_star = lanes_of<P>([&](int l) { return q[l]->g_star; });
  p.beta = lanes_of<P>([&](int l) { return q[l]->beta; });
  p.mu_s = lanes_of<P>([&](int l) { return q[l]->mu_s; });
  p.mu_r = lanes_of<P>([&](int l) { return q[l]->mu_r; });
  p.cohesion = lanes_of<P>([&](int l) { return q[l]->cohesion; });
  return p;
}

template <class Cohesion, class Rolling, class R>
DEM_INLINE void contact_law(const ContactInputT<R>& c, const PairParamsT<R>& p,
                        const ContactStep& step, R* history, ContactResultT<R>& result) {
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

  void wall_forces(const Particles& P, const MaterialTable& material, const ContactStep& step,
                   const WallContact* contacts, std::size_t count,
                   ContactResult* results) const override {
    if (avx512_cpu()) wall_packs8(P, material, step, contacts, count, results);
    else wall_packs4(P, material, step, contacts, count, results);
  }

  void pair_forces(PairForceArgs& a) const override {
    const bool periodic = a.domain.periodic(0) || a.domain.periodic(1) || a.domain.periodic(2);
    if (periodic) loop<true>(a);
    else loop<false>(a);
  }

 private:
  // Pairs run four at a time (one AVX instruction per operation where the CPU has AVX), or
  // eight where it has AVX-512: the contact law is a chain of square roots and divisions,
  // and more independent contacts keep more of them in flight; on CPUs whose AVX-512 units
  // are 512 bits wide, eight lanes also halve the square roots and divisions issued. Wall
  // contacts run the same way.
  static constexpr int kMaxLanes = 8;
  static constexpr int kBatch = 128;  // contacts per batch: its buffers stay in L1
  // Entries per batch buffer: the spare ones past kBatch take the dropped lanes of the last
  // pack. A fixed stride lets one register address every result column.
  static constexpr int kStride = kBatch + kMaxLanes;

  // Where a thread reads its partners j >= from: x[j - from] etc. (see PairScratch).
  struct Ghosts {
    std::size_t from;
    const Vec3 *x, *v, *omega;
  };

  // The material parameters of the last pack of type P, reused while the type pairs repeat
  // (always, with one particle type).
  template <class P, int Lanes>
  struct ParamsCache {
    const PairParams* of[Lanes] = {};
    PairParamsT<P> params;
  };

  // Touching pairs waiting for their contact law: particle i, its partner j, the list entry k,
  // and the results (force on i, torque on i, torque on j, overlap), one array per component
  // so that a pack of results is stored at once. Kept per thread between steps.
  struct Batch {
    int i[kStride], j[kStride], k[kStride];
    alignas(64) double out[10][kStride];
    int size = 0;
    bool ghosted = false;  // whether an entry's partner is read from the ghosts
    ParamsCache<Pack4, 4> params4;
    ParamsCache<Pack8, 8> params8;
    template <class P>
    auto& params_cache() {
      if constexpr (std::is_same_v<P, Pack4>) return params4;
      else return params8;
    }
  };

  // The contact laws of batch entries 0 .. b.size - 1, four at a time (AVX or plain x86-64)
  // or eight (AVX-512, where avx512_cpu()).
  template <bool Periodic, bool Ghosted>
  DEM_AVX_CLONES void contact_packs4(const PairForceArgs& a, const ContactStep& step, Batch& b,
                                     const Ghosts& g) const {
    for (int h = 0; h < b.size; h += 4)
      contact_pack<Periodic, Ghosted, Pack4, 4>(a, step, b, g, h, std::min(4, b.size - h));
  }
  template <bool Periodic, bool Ghosted>
  DEM_AVX512 void contact_packs8(const PairForceArgs& a, const ContactStep& step, Batch& b,
                                 const Ghosts& g) const {
    for (int h = 0; h < b.size; h += 8)
      contact_pack<Periodic, Ghosted, Pack8, 8>(a, step, b, g, h, std::min(8, b.size - h));
  }

  // The contact law of batch entries e0 .. e0 + count - 1 (count <= kLanes) in one pack; the
  // lanes past count repeat the last contact and are dropped. Packs are filled straight from
  // the particle arrays, and with Ghosted from the ghosts g for partners past the thread's share.
  template <bool Periodic, bool Ghosted, class Pack, int kLanes>
  DEM_INLINE void contact_pack(const PairForceArgs& a, const ContactStep& step, Batch& b,
                               const Ghosts& g, int e0, int count) const {
    const Particles& P = a.atoms;
    const Vec3* x = P.x.data();
    const Vec3* v = P.v.data();
    const Vec3* w = P.omega.data();
    const double* rad = P.radius.data();
    const double* mass = P.rmass.data();
    using V = Vec3T<Pack>;
    std::size_t ii[kLanes], jj[kLanes];
    int kk[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      const auto e = static_cast<std::size_t>(e0 + std::min(l, count - 1));
      ii[l] = static_cast<std::size_t>(b.i[e]);
      jj[l] = static_cast<std::size_t>(b.j[e]);
      kk[l] = b.k[e];
    }
    // The lambdas returning packs are always inlined: an out-of-line copy would be compiled
    // for plain x86-64 and pass the packs through memory.
    auto pack1 = [&](const double* of, const std::size_t* idx) DEM_INLINE_LAMBDA {
      return lanes_of<Pack>([&](int l) { return of[idx[l]]; });
    };
    auto pack3 = [&](const Vec3* of, const std::size_t* idx) DEM_INLINE_LAMBDA {
      return vec3_lanes<Pack>([&](int l) -> const Vec3& { return of[idx[l]]; });
    };
    // The partners' positions, velocities and spins.
    V xj, vj, wj;
    if constexpr (Ghosted) {
      const Vec3 *px[kLanes], *pv[kLanes], *pw[kLanes];
      for (int l = 0; l < kLanes; ++l) {
        const bool ghost = jj[l] >= g.from;
        const std::size_t at = ghost ? jj[l] - g.from : jj[l];
        px[l] = (ghost ? g.x : x) + at;
        pv[l] = (ghost ? g.v : v) + at;
        pw[l] = (ghost ? g.omega : w) + at;
      }
      auto pack3_at = [&](const Vec3* const* of) DEM_INLINE_LAMBDA {
        return vec3_lanes<Pack>([&](int l) -> const Vec3& { return *of[l]; });
      };
      xj = pack3_at(px);
      vj = pack3_at(pv);
      wj = pack3_at(pw);
    } else {
      xj = pack3(x, jj);
      vj = pack3(v, jj);
      wj = pack3(w, jj);
    }
    ContactInputT<Pack> c;
    V d;
    if constexpr (Periodic) {
      Vec3 dl[kLanes];
      for (int l = 0; l < kLanes; ++l)
        dl[l] = a.domain.minimum_image(x[ii[l]] - Vec3{xj.x[l], xj.y[l], xj.z[l]});
      std::size_t lane[kLanes];
      for (int l = 0; l < kLanes; ++l) lane[l] = static_cast<std::size_t>(l);
      d = pack3(dl, lane);
    } else {
      d = pack3(x, ii) - xj;
    }
    const Pack r = lane_sqrt(norm2(d));
    c.ri = pack1(rad, ii);
    c.rj = pack1(rad, jj);
    const Pack radsum = c.ri + c.rj;
    c.dist = r;
    c.n = (1.0 / r) * d;
    c.overlap = radsum - r;
    c.r_eff = c.ri * c.rj / radsum;
    Pack mi = pack1(mass, ii), mj = pack1(mass, jj);
    if (a.freeze_bit) {  // rare: a pair with a frozen particle has the other's mass
      double m[kLanes][2];
      for (int l = 0; l < kLanes; ++l) {
        m[l][0] = mass[ii[l]];
        m[l][1] = mass[jj[l]];
        if (P.mask[ii[l]] & a.freeze_bit) m[l][0] = 0.0;
        if (P.mask[jj[l]] & a.freeze_bit) m[l][0] = mass[ii[l]], m[l][1] = 0.0;
      }
      mi = lanes_of<Pack>([&](int l) { return m[l][0]; });
      mj = lanes_of<Pack>([&](int l) { return m[l][1]; });
    }
    c.m_eff = m_effective(mi, mj, a.freeze_bit != 0);
    c.cri = c.ri - 0.5 * c.overlap;
    c.crj = c.rj - 0.5 * c.overlap;
    c.v_rel = pack3(v, ii) - vj;
    c.omega_i = pack3(w, ii);
    c.omega_j = wj;
    auto& cache = b.template params_cache<Pack>();
    const PairParams* q[kLanes];
    bool same = true;
    for (int l = 0; l < kLanes; ++l) {
      q[l] = &a.material.get(P.type[ii[l]], P.type[jj[l]]);
      same = same && q[l] == cache.of[l];
    }
    if (!same) {
      cache.params = pack_params<Pack>(q);
      for (int l = 0; l < kLanes; ++l) cache.of[l] = q[l];
    }
    const PairParamsT<Pack>& p = cache.params;
    double* h[kLanes];
    for (int l = 0; l < kLanes; ++l)
      h[l] = a.list.history.data() + static_cast<std::size_t>(kk[l]) * kHistorySize;
    Pack hist[kHistorySize];
    for (int q6 = 0; q6 < kHistorySize; ++q6)
      hist[q6] = lanes_of<Pack>([&](int l) { return h[l][q6]; });
    ContactResultT<Pack> res;
    contact_law<Cohesion, Rolling>(c, p, step, hist, res);
    for (int l = 0; l < count; ++l)
      for (int q6 = 0; q6 < kHistorySize; ++q6) h[l][q6] = hist[q6][l];
    // Whole packs are stored; dropped lanes land in the spare entries past the batch. (Named
    // one by one: taking the results' addresses would keep them in memory.)
    res.force.x.store(&b.out[0][e0]);
    res.force.y.store(&b.out[1][e0]);
    res.force.z.store(&b.out[2][e0]);
    res.torque_i.x.store(&b.out[3][e0]);
    res.torque_i.y.store(&b.out[4][e0]);
    res.torque_i.z.store(&b.out[5][e0]);
    res.torque_j.x.store(&b.out[6][e0]);
    res.torque_j.y.store(&b.out[7][e0]);
    res.torque_j.z.store(&b.out[8][e0]);
    c.overlap.store(&b.out[9][e0]);
  }

  // The laws of wall contacts 0 .. count - 1, four at a time (AVX or plain x86-64) or eight
  // (AVX-512).
  DEM_AVX_CLONES void wall_packs4(const Particles& P, const MaterialTable& material,
                                  const ContactStep& step, const WallContact* contacts,
                                  std::size_t count, ContactResult* results) const {
    for (std::size_t h = 0; h < count; h += 4)
      wall_pack<Pack4, 4>(P, material, step, contacts, h, std::min<std::size_t>(4, count - h),
                          results);
  }
  DEM_AVX512 void wall_packs8(const Particles& P, const MaterialTable& material,
                              const ContactStep& step, const WallContact* contacts,
                              std::size_t count, ContactResult* results) const {
    for (std::size_t h = 0; h < count; h += 8)
      wall_pack<Pack8, 8>(P, material, step, contacts, h, std::min<std::size_t>(8, count - h),
                          results);
  }

  // Wall contacts e0 .. e0 + count - 1 (count <= kLanes) in one pack, set up as WallContact
  // says; the lanes past count repeat the last contact and are dropped.
  template <class Pack, int kLanes>
  DEM_INLINE void wall_pack(const Particles& P, const MaterialTable& material,
                            const ContactStep& step, const WallContact* contacts, std::size_t e0,
                            std::size_t count, ContactResult* results) const {
    using V = Vec3T<Pack>;
    const WallContact* w[kLanes];
    std::size_t i[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      w[l] = &contacts[e0 + std::min(static_cast<std::size_t>(l), count - 1)];
      i[l] = w[l]->i;
    }
    ContactInputT<Pack> c;
    c.wall = true;
    c.n = vec3_lanes<Pack>([&](int l) -> const Vec3& { return w[l]->normal; });
    c.overlap = lanes_of<Pack>([&](int l) { return w[l]->overlap; });
    c.dist = lanes_of<Pack>([&](int l) { return w[l]->dist; });
    c.ri = lanes_of<Pack>([&](int l) { return P.radius[i[l]]; });
    c.rj = 0.0;
    c.r_eff = c.ri;
    c.m_eff = lanes_of<Pack>([&](int l) { return P.rmass[i[l]]; });
    c.cri = c.ri - 0.5 * c.overlap;
    c.crj = 0.0;
    c.v_rel = vec3_lanes<Pack>([&](int l) -> const Vec3& { return P.v[i[l]]; }) -
              vec3_lanes<Pack>([&](int l) -> const Vec3& { return w[l]->wall_velocity; });
    c.omega_i = vec3_lanes<Pack>([&](int l) -> const Vec3& { return P.omega[i[l]]; });
    c.omega_j = V{Pack(0.0), Pack(0.0), Pack(0.0)};
    const PairParams* pair[kLanes];
    for (int l = 0; l < kLanes; ++l) pair[l] = &material.get(P.type[i[l]], w[l]->wall_type);
    const PairParamsT<Pack> p = pack_params<Pack>(pair);
    Pack hist[kHistorySize];
    for (int q = 0; q < kHistorySize; ++q)
      hist[q] = lanes_of<Pack>([&](int l) { return w[l]->history[q]; });
    ContactResultT<Pack> res;
    contact_law<Cohesion, Rolling>(c, p, step, hist, res);
    for (std::size_t l = 0; l < count; ++l) {
      const auto lane = static_cast<int>(l);
      double* h = w[lane]->history;
      for (int q = 0; q < kHistorySize; ++q) h[q] = hist[q][lane];
      ContactResult& r = results[e0 + l];
      r.fn = res.fn[lane];
      r.fn_limit = res.fn_limit[lane];
      r.kn = res.kn[lane];
      r.kt = res.kt[lane];
      r.gamma_t = res.gamma_t[lane];
      r.force = Vec3{res.force.x[lane], res.force.y[lane], res.force.z[lane]};
      r.torque_i = Vec3{res.torque_i.x[lane], res.torque_i.y[lane], res.torque_i.z[lane]};
      r.torque_j = Vec3{res.torque_j.x[lane], res.torque_j.y[lane], res.torque_j.z[lane]};
    }
  }

  // m_i m_j / (m_i + m_j); with fix freeze, a zero mass stands for a frozen particle and the
  // effective mass is the other one's.
  template <class Pack>
  DEM_INLINE static Pack m_effective(const Pack& mi, const Pack& mj, bool freeze) {
    const Pack m_eff = mi * mj / (mi + mj);
    if (!freeze) return m_eff;
    return select(mi > 0.0 && mj > 0.0, m_eff, mi + mj);
  }

  template <bool Periodic>
  void loop(PairForceArgs& a) const {
    Particles& P = a.atoms;
    const std::size_t n = P.size();
    const int nthreads = worker_threads(n);  // 1 for small systems
    PairScratch& scratch = a.scratch;
    scratch.size_for(a.list, n, nthreads);
    const long epoch = ++scratch.epoch;
    ContactStep step;
    step.options = spec().options;
    step.dt = a.dt;
    step.update_history = a.update_history;
    const bool wide = avx512_cpu();
    double worst_ratio = 0.0;
    long worst_tag = -1;
    long contacts = 0;
    // Per thread: one past the largest particle index it adds forces to.
    std::vector<std::size_t> touched_end(static_cast<std::size_t>(nthreads), 0);
#pragma omp parallel num_threads(nthreads) reduction(+ : contacts)
    {
      // Each thread takes the pairs of its own share of particles (the list's partition, as
      // every per-particle loop does); see PairScratch for how the shares exchange data.
      const int tid = omp_get_thread_num();
      const int team = omp_get_num_threads();  // may be fewer than asked for
      // Array pointers as locals of each thread, not shared variables of the parallel region:
      // those are reached through memory, and the byte stores to `touching` may alias
      // anything, so the compiler would reload each of them after every store.
      const Vec3* const x = P.x.data();
      const double* const rad = P.radius.data();
      const int* const first = a.list.first.data();
      const int* const partner = a.list.partner.data();
      std::uint8_t* const touching = a.list.touching.data();
      const ParticleShare own = a.list.partition().share(n, tid, team);
      // Windows and ghosts hold for the team they were found for; when fewer threads start,
      // each reads its partners from the particle arrays and finds its reach here.
      const bool windows = team == scratch.team;
      const auto me = static_cast<std::size_t>(tid);
      const std::size_t end_j = windows ? scratch.window_end[me] : reach_of(a.list, own).end;
      touched_end[me] = end_j;
      const std::size_t own_end = own.end;
      // Ghosts of this share's particles in the windows of the earlier threads.
      if (windows && tid > 0) {
        for (std::size_t th = 0; th < me; ++th) {
          const std::size_t base = a.list.partition().share(n, static_cast<int>(th), team).end;
          const std::size_t lo = std::max(base, own.begin);
          const std::size_t hi = std::min(scratch.window_end[th], own.end);
          for (std::size_t i = lo; i < hi; ++i) {
            scratch.ghost_x[th][i - base] = x[i];
            scratch.ghost_v[th][i - base] = P.v[i];
            scratch.ghost_omega[th][i - base] = P.omega[i];
          }
        }
        scratch.written[me].epoch.store(epoch, std::memory_order_release);
      }
      const Ghosts ghosts =
          windows && end_j > own_end
              ? Ghosts{own_end, scratch.ghost_x[me].data(), scratch.ghost_v[me].data(),
                       scratch.ghost_omega[me].data()}
              : Ghosts{n, nullptr, nullptr, nullptr};
      const std::size_t cross_from = windows ? scratch.cross_from[me] : own.end;
      const Vec3* const gx = ghosts.x;
      // Waits for the owners of this thread's window to have written its ghosts (they do so
      // first thing, and the window's pairs come last in this share: it hardly ever spins).
      auto await_ghosts = [&] {
        for (int th = tid + 1; th < team; ++th) {
          if (a.list.partition().share(n, th, team).begin >= end_j) break;
          while (scratch.written[static_cast<std::size_t>(th)].epoch.load(
                     std::memory_order_acquire) != epoch) {
          }
        }
      };
      Vec3* const f = P.f.data();
      Vec3* const t = P.torque.data();
      Vec3* const f_out = end_j > own.end ? scratch.force[tid].data() : f;
      Vec3* const t_out = end_j > own.end ? scratch.torque[tid].data() : t;
      std::fill(f + own.begin, f + own.end, Vec3{});
      std::fill(t + own.begin, t + own.end, Vec3{});
      std::fill(f_out + own.end, f_out + end_j, Vec3{});
      std::fill(t_out + own.end, t_out + end_j, Vec3{});
      // Contacts are gathered across particles into batches (pass 1), whose contact laws run
      // kLanes contacts at a time on packs (pass 2); their forces are then added in the order
      // of the list (pass 3), so the sums are those of one contact at a time.
      static thread_local Batch batch;
      batch.size = 0;
      batch.ghosted = false;
      // The material table may have changed.
      batch.params4 = {};
      batch.params8 = {};
      double my_ratio = 0.0;
      long my_tag = -1;
      int* const bi = batch.i;
      int* const bj = batch.j;
      int* const bk = batch.k;
      const auto& out = batch.out;
      const std::int64_t* const tag = P.tag.data();
      auto flush = [&]() {
        const int size = batch.size;
        if (wide && batch.ghosted) contact_packs8<Periodic, true>(a, step, batch, ghosts);
        else if (wide) contact_packs8<Periodic, false>(a, step, batch, ghosts);
        else if (batch.ghosted) contact_packs4<Periodic, true>(a, step, batch, ghosts);
        else contact_packs4<Periodic, false>(a, step, batch, ghosts);
        // The sums on i stay in registers while its contacts follow one another (partners
        // have j > i, so no other contact of the batch adds to f[i] meanwhile).
        for (int h = 0; h < size;) {
          const int i = bi[h];
          Vec3 fi = f[i], ti = t[i];
          const double ri = rad[i];
          for (; h < size && bi[h] == i; ++h) {
            const int j = bj[h];
            const bool inside = static_cast<std::size_t>(j) < own_end;
            Vec3* const fj = (inside ? f : f_out) + j;
            Vec3* const tj = (inside ? t : t_out) + j;
            const Vec3 force{out[0][h], out[1][h], out[2][h]};
            fi += force;
            *fj -= force;
            ti += Vec3{out[3][h], out[4][h], out[5][h]};
            *tj += Vec3{out[6][h], out[7][h], out[8][h]};
            const double rmin = std::min(ri, rad[j]);
            const double overlap = out[9][h];
            if (overlap > my_ratio * rmin) {
              my_ratio = overlap / rmin;
              my_tag = tag[i];
            }
          }
          f[i] = fi;
          t[i] = ti;
        }
        batch.size = 0;
        batch.ghosted = false;
      };
      // Pass 1 sorts the listed pairs of particle i into touching ones and flags which touch
      // (every one gathered here gets its contact law), without branching on the coin-flip
      // condition. As in LIGGGHTS, the history of a pair that opened is kept while the pair
      // stays in the list (a contact that closes again before the next neighbour build resumes
      // it); the build drops it unless the pair touches at the build's positions (see
      // NeighborList::build). A full batch is flushed, also between the pairs of one particle:
      // its sums continue in the same order. With ghosts (the particles from cross_from on),
      // partners past the share are read from them.
      auto gather = [&](std::size_t i, auto with_ghosts) {
        constexpr bool kGhosts = decltype(with_ghosts)::value;
        int k = first[i];
        const int k_end = first[i + 1];
        if (k == k_end) return;
        const Vec3 xi = x[i];
        const double ri = rad[i];
        if constexpr (kGhosts) batch.ghosted = true;
        while (k < k_end) {
          if (batch.size == kBatch) {
            flush();
            if constexpr (kGhosts) batch.ghosted = true;
          }
          const int stop = std::min(k_end, k + (kBatch - batch.size));
          int m = batch.size;
          for (; k < stop; ++k) {
            const int j = partner[k];
            Vec3 d = xi;
            if constexpr (kGhosts) {
              const auto uj = static_cast<std::size_t>(j);
              d -= uj >= ghosts.from ? gx[uj - ghosts.from] : x[uj];
            } else {
              d -= x[j];
            }
            if constexpr (Periodic) d = a.domain.minimum_image(d);
            const double radsum = ri + rad[j];
            const bool apart = norm2(d) >= radsum * radsum;
            bi[m] = static_cast<int>(i);
            bj[m] = j;
            bk[m] = k;
            m += !apart;
            touching[k] = static_cast<std::uint8_t>(!apart);
          }
          contacts += m - batch.size;
          batch.size = m;
        }
      };
      for (std::size_t i = own.begin; i < cross_from; ++i) gather(i, std::false_type{});
      if (cross_from < own.end) {
        await_ghosts();
        for (std::size_t i = cross_from; i < own.end; ++i) gather(i, std::true_type{});
      }
      flush();
#pragma omp critical
      if (my_ratio > worst_ratio) {
        worst_ratio = my_ratio;
        worst_tag = my_tag;
      }
      if (team > 1) {
        // Every thread adds the sums of the earlier threads on its own particles, in thread
        // order: the sum over threads does not depend on scheduling.
#pragma omp barrier
        // Only the earlier threads add into this share, and only up to their largest partner.
        std::size_t reach = own.begin;
        for (std::size_t th = 0; th < me; ++th) reach = std::max(reach, touched_end[th]);
        reach = std::min(reach, own.end);
        for (std::size_t i = own.begin; i < reach; ++i) {
          Vec3 fs, ts;
          for (std::size_t th = 0; th < me; ++th) {
            if (i >= touched_end[th]) continue;
            fs += scratch.force[th][i];
            ts += scratch.torque[th][i];
          }
          f[i] += fs;
          t[i] += ts;
        }
      }
    }
    a.max_overlap_ratio = worst_ratio;
    a.max_overlap_tag = worst_tag;
    a.contacts = contacts;
  }
};

}  // namespace

void PairScratch::size_for(const NeighborList& list, std::size_t n_now, int nthreads) {
  const int size = std::max(nthreads, 1);
  if (&list == list_of && list.builds() == list_build && n_now == n && size == team) return;
  list_of = &list;
  list_build = list.builds();
  n = n_now;
  team = size;
  const auto t_count = static_cast<std::size_t>(team);
  written = std::make_unique<Flag[]>(t_count);
  window_end.assign(t_count, n);
  cross_from.assign(t_count, n);
  for (auto* per_thread : {&force, &torque, &ghost_x, &ghost_v, &ghost_omega})
    per_thread->resize(t_count);
  for (int t = 0; t < team; ++t) {
    const auto tt = static_cast<std::size_t>(t);
    const ParticleShare own = list.partition().share(n, t, team);
    const ShareReach reach = reach_of(list, own);
    window_end[tt] = reach.end;
    cross_from[tt] = reach.from;
    if (t + 1 < team) {
      force[tt].resize(n);
      torque[tt].resize(n);
    }
    for (auto* ghost : {&ghost_x, &ghost_v, &ghost_omega})
      (*ghost)[tt].resize(reach.end - own.end);
  }
}

int contact_pack_lanes() { return avx512_cpu() ? 8 : 4; }

std::unique_ptr<ContactModel> make_contact_model(const ModelSpec& spec) {
  if (spec.cohesion_sjkr && spec.rolling_epsd2)
    return std::make_unique<ComposedModel<CohesionSjkr, RollingEpsd2>>(spec);
  if (spec.cohesion_sjkr) return std::make_unique<ComposedModel<CohesionSjkr, RollingNone>>(spec);
  if (spec.rolling_epsd2) return std::make_unique<ComposedModel<CohesionNone, RollingEpsd2>>(spec);
  return std::make_unique<ComposedModel<CohesionNone, RollingNone>>(spec);
}

}  // namespace dem
