// Tests of the packs the pair loop runs the contact law on (core/simd.h): four contacts on a
// Pack4 give bit for bit the results of the same sub-models run on each contact as doubles.
#include <cstdint>
#include <cstring>
#include <random>

#include "contact/cohesion_sjkr.h"
#include "contact/normal_hertz.h"
#include "contact/rolling_epsd2.h"
#include "contact/tangential_history.h"
#include "core/simd.h"
#include "unit_test.h"

using namespace dem;

namespace {

bool same_bits(double a, double b) {
  std::uint64_t x, y;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

template <class R>
DEM_INLINE void law(const ContactInputT<R>& c, const PairParamsT<R>& p, const ContactStep& step,
                    R* history, ContactResultT<R>& result) {
  NormalHertz::apply(c, p, step, history, result);
  CohesionSjkr::apply(c, p, step, history, result);
  TangentialHistory::apply(c, p, step, history, result);
  RollingEpsd2::apply(c, p, step, history, result);
}

// The pack version compiled as the engine compiles contact_pack: in an AVX copy where the CPU
// has AVX, so that the 256-bit instructions are what is tested.
DEM_AVX_CLONES void law_on_pack(const ContactInputT<Pack4>& c, const PairParamsT<Pack4>& p,
                                const ContactStep& step, Pack4* history,
                                ContactResultT<Pack4>& result) {
  law(c, p, step, history, result);
}

struct Contact {
  ContactInput c;
  PairParams p;
  double history[kHistorySize];
};

// A random pair contact: small or large overlaps, springs from empty to far past the Coulomb
// and rolling caps, cohesion on in about half of them.
Contact random_contact(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  Contact k;
  Vec3 n{u(rng), u(rng), u(rng)};
  n = (1.0 / norm(n)) * n;
  k.c.n = n;
  k.c.ri = 1e-3 * (1.0 + pos(rng));
  k.c.rj = 1e-3 * (1.0 + pos(rng));
  k.c.overlap = 1e-5 * pos(rng) * (pos(rng) < 0.1 ? 10.0 : 1.0);
  k.c.dist = k.c.ri + k.c.rj - k.c.overlap;
  k.c.r_eff = k.c.ri * k.c.rj / (k.c.ri + k.c.rj);
  k.c.m_eff = 1e-5 * (0.5 + pos(rng));
  k.c.cri = k.c.ri - 0.5 * k.c.overlap;
  k.c.crj = k.c.rj - 0.5 * k.c.overlap;
  k.c.v_rel = Vec3{u(rng), u(rng), u(rng)};
  k.c.omega_i = 100.0 * Vec3{u(rng), u(rng), u(rng)};
  k.c.omega_j = 100.0 * Vec3{u(rng), u(rng), u(rng)};
  k.p.y_star = 5e6 * (0.5 + pos(rng));
  k.p.g_star = 0.4 * k.p.y_star;
  k.p.beta = -0.3 * pos(rng);
  k.p.mu_s = pos(rng);
  k.p.mu_r = pos(rng);
  k.p.cohesion = pos(rng) < 0.5 ? 0.0 : 5e4 * pos(rng);
  const double reach = pos(rng) < 0.3 ? 0.0 : 1e-5 * std::pow(10.0, 3.0 * pos(rng));
  for (int q = 0; q < 3; ++q) k.history[q] = reach * u(rng);
  for (int q = 3; q < 6; ++q) k.history[q] = 1e-6 * reach * 1e5 * u(rng);
  return k;
}

Pack4 lanes(const Contact* k, double (*field)(const Contact&)) {
  return Pack4(field(k[0]), field(k[1]), field(k[2]), field(k[3]));
}

}  // namespace

TEST_CASE("simd: Pack4 operations round lane by lane as double") {
  const double a[4] = {1.5, -0.0, 3e-310, -7.25};  // includes -0 and a subnormal
  const double b[4] = {0.1, 2.0, -3e-310, 1e300};
  const Pack4 pa(a[0], a[1], a[2], a[3]), pb(b[0], b[1], b[2], b[3]);
  const Pack4 sum = pa + pb, diff = pa - pb, prod = pa * pb, quot = pa / pb;
  const Pack4 root = lane_sqrt(pb * pb), mag = lane_abs(pa);
  const Pack4 pick = select(pa > pb, pa, pb), low = select(pa < pb, pa, pb);
  for (int l = 0; l < 4; ++l) {
    CHECK(same_bits(sum[l], a[l] + b[l]));
    CHECK(same_bits(diff[l], a[l] - b[l]));
    CHECK(same_bits(prod[l], a[l] * b[l]));
    CHECK(same_bits(quot[l], a[l] / b[l]));
    CHECK(same_bits(root[l], std::sqrt(b[l] * b[l])));
    CHECK(same_bits(mag[l], std::fabs(a[l])));
    CHECK(same_bits(pick[l], a[l] > b[l] ? a[l] : b[l]));
    CHECK(same_bits(low[l], a[l] < b[l] ? a[l] : b[l]));
  }
  CHECK(any(pa > pb));
  CHECK(!any(pa > Pack4(1e301)));
  CHECK(any((pa > Pack4(0.0)) && (pb > Pack4(0.0))));        // lane 0 only
  CHECK(!any((pa > Pack4(2.0)) && (pb > Pack4(0.0))));       // no lane has both
}

TEST_CASE("simd: the contact law on four contacts in a Pack4 equals it on each contact") {
  std::mt19937_64 rng(20261127);
  ContactStep step;
  step.dt = 1e-5;
  int sliding = 0, capped = 0, cohesive = 0, checked = 0;
  for (int round = 0; round < 500; ++round) {
    step.update_history = round % 5 != 0;
    step.options.tangential_reduce = round % 3 == 0;
    Contact k[4];
    for (auto& kk : k) kk = random_contact(rng);
    // Scalar reference, one contact at a time.
    ContactResult ref[4];
    double ref_history[4][kHistorySize];
    for (int l = 0; l < 4; ++l) {
      std::memcpy(ref_history[l], k[l].history, sizeof ref_history[l]);
      law(k[l].c, k[l].p, step, ref_history[l], ref[l]);
      // At a cap the stored spring or torque has exactly the capped magnitude.
      const double* h = ref_history[l];
      const double ft_max = k[l].p.mu_s * std::fabs(ref[l].fn_limit);
      const double m_max = k[l].p.mu_r * k[l].c.r_eff * std::fabs(ref[l].fn_limit);
      const double ft = ref[l].kt * norm(Vec3{h[0], h[1], h[2]});
      const double m = norm(Vec3{h[3], h[4], h[5]});
      sliding += step.update_history && ft_max > 0.0 && std::fabs(ft - ft_max) < 1e-9 * ft_max;
      capped += step.update_history && m_max > 0.0 && std::fabs(m - m_max) < 1e-9 * m_max;
      cohesive += k[l].p.cohesion > 0.0;
    }
    // The same four on one pack.
    ContactInputT<Pack4> c;
    using V = Vec3T<Pack4>;
    auto vec = [&](Vec3 ContactInput::*m) {
      return V{Pack4((k[0].c.*m).x, (k[1].c.*m).x, (k[2].c.*m).x, (k[3].c.*m).x),
               Pack4((k[0].c.*m).y, (k[1].c.*m).y, (k[2].c.*m).y, (k[3].c.*m).y),
               Pack4((k[0].c.*m).z, (k[1].c.*m).z, (k[2].c.*m).z, (k[3].c.*m).z)};
    };
    c.n = vec(&ContactInput::n);
    c.v_rel = vec(&ContactInput::v_rel);
    c.omega_i = vec(&ContactInput::omega_i);
    c.omega_j = vec(&ContactInput::omega_j);
    c.overlap = lanes(k, [](const Contact& x) { return x.c.overlap; });
    c.dist = lanes(k, [](const Contact& x) { return x.c.dist; });
    c.r_eff = lanes(k, [](const Contact& x) { return x.c.r_eff; });
    c.m_eff = lanes(k, [](const Contact& x) { return x.c.m_eff; });
    c.ri = lanes(k, [](const Contact& x) { return x.c.ri; });
    c.rj = lanes(k, [](const Contact& x) { return x.c.rj; });
    c.cri = lanes(k, [](const Contact& x) { return x.c.cri; });
    c.crj = lanes(k, [](const Contact& x) { return x.c.crj; });
    PairParamsT<Pack4> p;
    p.y_star = lanes(k, [](const Contact& x) { return x.p.y_star; });
    p.g_star = lanes(k, [](const Contact& x) { return x.p.g_star; });
    p.beta = lanes(k, [](const Contact& x) { return x.p.beta; });
    p.mu_s = lanes(k, [](const Contact& x) { return x.p.mu_s; });
    p.mu_r = lanes(k, [](const Contact& x) { return x.p.mu_r; });
    p.cohesion = lanes(k, [](const Contact& x) { return x.p.cohesion; });
    Pack4 hist[kHistorySize];
    for (int q = 0; q < kHistorySize; ++q)
      hist[q] = Pack4(k[0].history[q], k[1].history[q], k[2].history[q], k[3].history[q]);
    ContactResultT<Pack4> res;
    law_on_pack(c, p, step, hist, res);
    for (int l = 0; l < 4; ++l) {
      bool same = same_bits(res.fn[l], ref[l].fn) && same_bits(res.fn_limit[l], ref[l].fn_limit);
      const Pack4* got[9] = {&res.force.x,    &res.force.y,    &res.force.z,
                             &res.torque_i.x, &res.torque_i.y, &res.torque_i.z,
                             &res.torque_j.x, &res.torque_j.y, &res.torque_j.z};
      const double want[9] = {ref[l].force.x,    ref[l].force.y,    ref[l].force.z,
                              ref[l].torque_i.x, ref[l].torque_i.y, ref[l].torque_i.z,
                              ref[l].torque_j.x, ref[l].torque_j.y, ref[l].torque_j.z};
      for (int q = 0; q < 9; ++q) same = same && same_bits((*got[q])[l], want[q]);
      for (int q = 0; q < kHistorySize; ++q)
        same = same && same_bits(hist[q][l], ref_history[l][q]);
      CHECK(same);
      ++checked;
    }
  }
  CHECK_EQ(checked, 2000);
  // The draw reaches every branch: sliding springs, capped rolling torques, cohesive lanes.
  CHECK(sliding > 100);
  CHECK(capped > 100);
  CHECK(cohesive > 500);
}
