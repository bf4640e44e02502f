#pragma once
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/vec3.h"

// Inlined into the caller whatever the compiler's size heuristics say: the contact sub-models
// on packs are worth running only as one instruction stream with the code that fills the packs.
#if defined(__GNUC__)
#define DEM_INLINE [[gnu::always_inline]] inline
#define DEM_INLINE_LAMBDA __attribute__((always_inline))
#else
#define DEM_INLINE inline
#define DEM_INLINE_LAMBDA
#endif

// A function compiled twice, for AVX and for plain x86-64, the copy chosen once at start-up by
// the CPU: the AVX copy encodes the same operations with three operands, which saves the
// register copies of the two-operand SSE2 forms. AVX has no fused multiply-add (that is FMA,
// not enabled here), so both copies round identically.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define DEM_AVX_CLONES __attribute__((target_clones("avx", "default")))
#else
#define DEM_AVX_CLONES
#endif

// A function compiled for AVX-512 only, called where avx512_cpu() says the CPU has it: eight
// doubles per instruction. The build compiles without floating-point contraction
// (-ffp-contract=off), so the fused multiply-adds AVX-512 brings are never formed and such a
// function rounds exactly as the other copies.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define DEM_AVX512 __attribute__((target("avx512f")))
#else
#define DEM_AVX512
#endif

namespace dem {

// Whether the DEM_AVX512 copies run. DEM_ENGINE_NO_AVX512 set (to anything) keeps the
// four-lane copies on such a CPU too, so the two can be compared on one machine.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
inline bool avx512_cpu() {
  static const bool use =
      __builtin_cpu_supports("avx512f") && std::getenv("DEM_ENGINE_NO_AVX512") == nullptr;
  return use;
}
#else
inline bool avx512_cpu() { return false; }
#endif

// Two doubles processed in lockstep (one SSE2 instruction on x86-64, which every x86-64 CPU has;
// plain lane loops elsewhere). Add, subtract, multiply, divide and sqrt are correctly rounded
// IEEE operations whatever the width, so code run on packs gives bit for bit the results of the
// same code run on doubles, lane by lane; no operation here is reassociated or fused.
struct Pack2 {
  typedef double Raw __attribute__((vector_size(16)));
  Raw v;

  Pack2() : v{0.0, 0.0} {}
  Pack2(double s) : v{s, s} {}  // NOLINT: implicit broadcast, as a double mixes with a pack
  Pack2(double a, double b) : v{a, b} {}
  explicit Pack2(Raw r) : v(r) {}
  double operator[](int lane) const { return v[lane]; }
  void store(double* to) const { std::memcpy(to, &v, sizeof v); }
  Pack2& operator+=(const Pack2& o) { v += o.v; return *this; }
  Pack2& operator-=(const Pack2& o) { v -= o.v; return *this; }
  Pack2& operator*=(const Pack2& o) { v *= o.v; return *this; }
};

// Lane mask of a pack comparison: all bits set where it holds.
struct Mask2 {
  Pack2::Raw m;
};

inline Pack2 operator+(const Pack2& a, const Pack2& b) { return Pack2(a.v + b.v); }
inline Pack2 operator-(const Pack2& a, const Pack2& b) { return Pack2(a.v - b.v); }
inline Pack2 operator*(const Pack2& a, const Pack2& b) { return Pack2(a.v * b.v); }
inline Pack2 operator/(const Pack2& a, const Pack2& b) { return Pack2(a.v / b.v); }
inline Pack2 operator-(const Pack2& a) { return Pack2(-a.v); }

#if defined(__SSE2__)
// Masks and selections with SSE2 bit operations: written on generic vectors, GCC turns a
// bitwise select into one conditional move per lane through the integer registers.
inline __m128d raw_sse(const Pack2::Raw& r) { return reinterpret_cast<__m128d>(r); }
inline Pack2::Raw raw_of(__m128d r) { return reinterpret_cast<Pack2::Raw>(r); }
inline Mask2 operator>(const Pack2& a, const Pack2& b) {
  return {raw_of(_mm_cmpgt_pd(raw_sse(a.v), raw_sse(b.v)))};
}
inline Mask2 operator<(const Pack2& a, const Pack2& b) {
  return {raw_of(_mm_cmplt_pd(raw_sse(a.v), raw_sse(b.v)))};
}
inline Mask2 operator&&(const Mask2& a, const Mask2& b) {
  return {raw_of(_mm_and_pd(raw_sse(a.m), raw_sse(b.m)))};
}
inline Pack2 lane_sqrt(const Pack2& a) { return Pack2(raw_of(_mm_sqrt_pd(raw_sse(a.v)))); }
// |a|: clears the sign bits, exactly as std::fabs.
inline Pack2 lane_abs(const Pack2& a) {
  return Pack2(raw_of(_mm_andnot_pd(_mm_set1_pd(-0.0), raw_sse(a.v))));
}
// a where the mask is set, b elsewhere (bitwise, so both are exact copies).
inline Pack2 select(const Mask2& mask, const Pack2& a, const Pack2& b) {
  const __m128d m = raw_sse(mask.m);
  return Pack2(raw_of(_mm_or_pd(_mm_and_pd(m, raw_sse(a.v)), _mm_andnot_pd(m, raw_sse(b.v)))));
}
inline bool any(const Mask2& mask) { return _mm_movemask_pd(raw_sse(mask.m)) != 0; }
#else
inline Pack2::Raw mask_of(bool l0, bool l1) {
  std::int64_t bits[2] = {l0 ? -1 : 0, l1 ? -1 : 0};
  Pack2::Raw r;
  std::memcpy(&r, bits, sizeof r);
  return r;
}
inline bool lane_set(const Mask2& mask, int lane) {
  std::int64_t bits;
  std::memcpy(&bits, reinterpret_cast<const double*>(&mask.m) + lane, sizeof bits);
  return bits != 0;
}
inline Mask2 operator>(const Pack2& a, const Pack2& b) {
  return {mask_of(a.v[0] > b.v[0], a.v[1] > b.v[1])};
}
inline Mask2 operator<(const Pack2& a, const Pack2& b) {
  return {mask_of(a.v[0] < b.v[0], a.v[1] < b.v[1])};
}
inline Mask2 operator&&(const Mask2& a, const Mask2& b) {
  return {mask_of(lane_set(a, 0) && lane_set(b, 0), lane_set(a, 1) && lane_set(b, 1))};
}
inline Pack2 lane_sqrt(const Pack2& a) { return Pack2(std::sqrt(a.v[0]), std::sqrt(a.v[1])); }
inline Pack2 lane_abs(const Pack2& a) { return Pack2(std::fabs(a.v[0]), std::fabs(a.v[1])); }
inline Pack2 select(const Mask2& mask, const Pack2& a, const Pack2& b) {
  return Pack2(lane_set(mask, 0) ? a.v[0] : b.v[0], lane_set(mask, 1) ? a.v[1] : b.v[1]);
}
inline bool any(const Mask2& mask) { return lane_set(mask, 0) || lane_set(mask, 1); }
#endif

// Four doubles in lockstep, written on GCC's generic vectors: in the AVX copy of a function
// (DEM_AVX_CLONES) each operation is one 256-bit instruction, in plain x86-64 two SSE2 ones.
// Every operation rounds lane by lane as double does (as Pack2); the lane-wise sqrt below
// compiles to one vector square root. Passed by value only inside inlined code, so the ABI
// note GCC gives for 32-byte vectors without AVX (-Wpsabi) does not apply.
struct Pack4 {
  typedef double Raw __attribute__((vector_size(32)));
  typedef std::int64_t Bits __attribute__((vector_size(32)));
  Raw v;

  Pack4() : v{0.0, 0.0, 0.0, 0.0} {}
  Pack4(double s) : v{s, s, s, s} {}  // NOLINT: implicit broadcast, as for Pack2
  Pack4(double a, double b, double c, double d) : v{a, b, c, d} {}
  explicit Pack4(Raw r) : v(r) {}
  double operator[](int lane) const { return v[lane]; }
  void store(double* to) const { std::memcpy(to, &v, sizeof v); }
  Pack4& operator+=(const Pack4& o) { v += o.v; return *this; }
  Pack4& operator-=(const Pack4& o) { v -= o.v; return *this; }
  Pack4& operator*=(const Pack4& o) { v *= o.v; return *this; }
};

// Lane mask of a Pack4 comparison: all bits set where it holds.
struct Mask4 {
  Pack4::Bits m;
};

inline Pack4 operator+(const Pack4& a, const Pack4& b) { return Pack4(a.v + b.v); }
inline Pack4 operator-(const Pack4& a, const Pack4& b) { return Pack4(a.v - b.v); }
inline Pack4 operator*(const Pack4& a, const Pack4& b) { return Pack4(a.v * b.v); }
inline Pack4 operator/(const Pack4& a, const Pack4& b) { return Pack4(a.v / b.v); }
inline Pack4 operator-(const Pack4& a) { return Pack4(-a.v); }
inline Mask4 operator>(const Pack4& a, const Pack4& b) { return {a.v > b.v}; }
inline Mask4 operator<(const Pack4& a, const Pack4& b) { return {a.v < b.v}; }
inline Mask4 operator&&(const Mask4& a, const Mask4& b) { return {a.m & b.m}; }
inline Pack4 lane_sqrt(const Pack4& a) {
  return Pack4(std::sqrt(a.v[0]), std::sqrt(a.v[1]), std::sqrt(a.v[2]), std::sqrt(a.v[3]));
}
// |a|: clears the sign bits, exactly as std::fabs.
inline Pack4 lane_abs(const Pack4& a) {
  const Pack4::Bits magnitude = ~Pack4::Bits{INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN};
  return Pack4(reinterpret_cast<Pack4::Raw>(reinterpret_cast<Pack4::Bits>(a.v) & magnitude));
}
// a where the mask is set, b elsewhere (exact copies).
inline Pack4 select(const Mask4& mask, const Pack4& a, const Pack4& b) {
  return Pack4(mask.m ? a.v : b.v);
}
inline bool any(const Mask4& mask) { return (mask.m[0] | mask.m[1] | mask.m[2] | mask.m[3]) != 0; }

// Eight doubles in lockstep, as Pack4: one 512-bit instruction per operation in an AVX-512
// function (DEM_AVX512), split into narrower ones elsewhere. Its operations are always
// inlined: a call from an AVX-512 function to an out-of-line copy compiled for plain x86-64
// would pass every pack through memory.
struct Pack8 {
  typedef double Raw __attribute__((vector_size(64)));
  typedef std::int64_t Bits __attribute__((vector_size(64)));
  Raw v;

  DEM_INLINE Pack8() : v{0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0} {}
  DEM_INLINE Pack8(double s) : v{s, s, s, s, s, s, s, s} {}  // NOLINT: implicit broadcast
  DEM_INLINE Pack8(double a, double b, double c, double d, double e, double f, double g, double h)
      : v{a, b, c, d, e, f, g, h} {}
  DEM_INLINE explicit Pack8(Raw r) : v(r) {}
  DEM_INLINE double operator[](int lane) const { return v[lane]; }
  DEM_INLINE void store(double* to) const { std::memcpy(to, &v, sizeof v); }
  DEM_INLINE Pack8& operator+=(const Pack8& o) { v += o.v; return *this; }
  DEM_INLINE Pack8& operator-=(const Pack8& o) { v -= o.v; return *this; }
  DEM_INLINE Pack8& operator*=(const Pack8& o) { v *= o.v; return *this; }
};

DEM_INLINE Pack8 operator+(const Pack8& a, const Pack8& b) { return Pack8(a.v + b.v); }
DEM_INLINE Pack8 operator-(const Pack8& a, const Pack8& b) { return Pack8(a.v - b.v); }
DEM_INLINE Pack8 operator*(const Pack8& a, const Pack8& b) { return Pack8(a.v * b.v); }
DEM_INLINE Pack8 operator/(const Pack8& a, const Pack8& b) { return Pack8(a.v / b.v); }
DEM_INLINE Pack8 operator-(const Pack8& a) { return Pack8(-a.v); }
DEM_INLINE Pack8 lane_sqrt(const Pack8& a) {
  Pack8 r;
  for (int l = 0; l < 8; ++l) r.v[l] = std::sqrt(a.v[l]);
  return r;
}
// |a|: clears the sign bits, exactly as std::fabs.
DEM_INLINE Pack8 lane_abs(const Pack8& a) {
  const Pack8::Bits sign = Pack8::Bits{} + INT64_MIN;
  return Pack8(reinterpret_cast<Pack8::Raw>(reinterpret_cast<Pack8::Bits>(a.v) & ~sign));
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
// Lane mask of a Pack8 comparison, one bit per lane. Written on generic vectors, GCC compares
// lane by lane inside the contact law; these use the AVX-512 comparison and blend instead.
// The builtins are declared by switching the target on and off once; they expand only inside
// the AVX-512 functions that use Pack8 (anywhere else the build fails).
#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC pop_options
struct Mask8 {
  unsigned char bits;
};
// Predicates 0x0e (greater) and 0x01 (less), ordered and signalling, are those of the C
// comparisons: false where a lane is NaN.
DEM_INLINE Mask8 operator>(const Pack8& a, const Pack8& b) {
  return {__builtin_ia32_cmppd512_mask(a.v, b.v, 0x0e, 0xff, 4)};
}
DEM_INLINE Mask8 operator<(const Pack8& a, const Pack8& b) {
  return {__builtin_ia32_cmppd512_mask(a.v, b.v, 0x01, 0xff, 4)};
}
DEM_INLINE Mask8 operator&&(const Mask8& a, const Mask8& b) {
  return {static_cast<unsigned char>(a.bits & b.bits)};
}
// a where the mask is set, b elsewhere (exact copies).
DEM_INLINE Pack8 select(const Mask8& mask, const Pack8& a, const Pack8& b) {
  return Pack8(__builtin_ia32_blendmpd_512_mask(b.v, a.v, mask.bits));
}
DEM_INLINE bool any(const Mask8& mask) { return mask.bits != 0; }
#else
// Elsewhere Pack8 is not used (avx512_cpu() is false); generic masks as for Pack4.
struct Mask8 {
  Pack8::Bits m;
};
DEM_INLINE Mask8 operator>(const Pack8& a, const Pack8& b) { return {a.v > b.v}; }
DEM_INLINE Mask8 operator<(const Pack8& a, const Pack8& b) { return {a.v < b.v}; }
DEM_INLINE Mask8 operator&&(const Mask8& a, const Mask8& b) { return {a.m & b.m}; }
DEM_INLINE Pack8 select(const Mask8& mask, const Pack8& a, const Pack8& b) {
  return Pack8(mask.m ? a.v : b.v);
}
DEM_INLINE bool any(const Mask8& mask) {
  std::int64_t bits = 0;
  for (int l = 0; l < 8; ++l) bits |= mask.m[l];
  return bits != 0;
}
#endif

// The same operations on plain doubles, so that contact code can be written once for both.
inline double lane_sqrt(double a) { return std::sqrt(a); }
inline double lane_abs(double a) { return std::fabs(a); }
inline double select(bool mask, double a, double b) { return mask ? a : b; }
inline bool any(bool mask) { return mask; }

// A vector of packs: lane l of each component is the vector of one contact. Always inlined,
// as the pack operations (see Pack8).
template <class R>
struct Vec3T {
  R x, y, z;
  Vec3T() = default;
  DEM_INLINE Vec3T(const R& a, const R& b, const R& c) : x(a), y(b), z(c) {}
  DEM_INLINE Vec3T& operator+=(const Vec3T& o) { x += o.x; y += o.y; z += o.z; return *this; }
  DEM_INLINE Vec3T& operator-=(const Vec3T& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  DEM_INLINE Vec3T& operator*=(const R& s) { x *= s; y *= s; z *= s; return *this; }
};

template <class R> DEM_INLINE Vec3T<R> operator+(Vec3T<R> a, const Vec3T<R>& b) { return a += b; }
template <class R> DEM_INLINE Vec3T<R> operator-(Vec3T<R> a, const Vec3T<R>& b) { return a -= b; }
template <class R> DEM_INLINE Vec3T<R> operator-(const Vec3T<R>& a) { return {-a.x, -a.y, -a.z}; }
// R is taken from the vector only, so that a double scalar broadcasts.
template <class T> struct NoDeduce { using type = T; };
// Vec3 multiplies each component by the scalar on the right (a.x * s); so do these.
template <class R> DEM_INLINE Vec3T<R> operator*(Vec3T<R> a, const typename NoDeduce<R>::type& s) {
  return a *= s;
}
template <class R> DEM_INLINE Vec3T<R> operator*(const typename NoDeduce<R>::type& s, Vec3T<R> a) {
  return a *= s;
}
template <class R> DEM_INLINE R dot(const Vec3T<R>& a, const Vec3T<R>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class R> DEM_INLINE Vec3T<R> cross(const Vec3T<R>& a, const Vec3T<R>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class R> DEM_INLINE R norm2(const Vec3T<R>& a) { return dot(a, a); }
template <class R> DEM_INLINE R norm(const Vec3T<R>& a) { return lane_sqrt(dot(a, a)); }
template <class R, class M>
DEM_INLINE Vec3T<R> select(const M& mask, const Vec3T<R>& a, const Vec3T<R>& b) {
  return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}
inline Vec3 select(bool mask, const Vec3& a, const Vec3& b) { return mask ? a : b; }

// The vector type of contact code on R: Vec3 itself for doubles.
template <class R>
using Vec3Of = std::conditional_t<std::is_same_v<R, double>, Vec3, Vec3T<R>>;

}  // namespace dem
