// The batched cohort update (UnitModel::AdvanceCohorts, SumTension): cohorts as a structure of
// arrays, one SIMD register of cohorts per batch (2 lanes with the portable SSE2 baseline, 4 with
// AVX). Every lane performs exactly the operations of SolvePhase and AdvanceUnitWithDecay
// (unit_model.cc) on one cohort, in the same order and without contraction (-ffp-contract=off,
// plugin/CMakeLists.txt), so each cohort's result is bit-identical to the scalar update.
// Branches become lane masks; a lane whose Newton iteration has stopped keeps its values while
// the others continue.
#include "plugin/unit_batch.h"

#include <cmath>
#include <cstring>

#include "plugin/unit_model.h"

// batch_base in the normal compile, batch_avx2 in the AVX2 clone (plugin/CMakeLists.txt).
#ifndef RECRUIT_SMA_BATCH_NS
#define RECRUIT_SMA_BATCH_NS batch_base
#endif

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace recruit::sma::RECRUIT_SMA_BATCH_NS {
namespace {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // vectors are passed only between inlined functions

// Lane masks (type Mask) are vectors of doubles with all bits set or clear (the comparison
// instructions' result), combined with bit operations; in the AVX-512 clone they are mask
// registers. ToVd / ToMask convert them to and from all-bits vectors (to store them).
#if defined(RECRUIT_SMA_LANES8)
// The AVX-512 clone (AdvanceCohorts only): 8 lanes, comparisons into mask registers, which
// select (blend), zero lanes and combine without vector instructions of their own.
constexpr int kLanes = 8;
using Vd = __m512d;
using Mask = __mmask8;
inline Vd Splat(double x) { return _mm512_set1_pd(x); }
inline Vd Load(const double* p) { return _mm512_loadu_pd(p); }
inline void Store(double* p, Vd v) { _mm512_storeu_pd(p, v); }
inline Vd ToVd(Mask k) { return _mm512_castsi512_pd(_mm512_movm_epi64(k)); }
inline Mask ToMask(Vd v) { return _mm512_movepi64_mask(_mm512_castpd_si512(v)); }
inline Mask Lt(Vd a, Vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
inline Mask Le(Vd a, Vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_LE_OQ); }
inline Mask Ne(Vd a, Vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_NEQ_UQ); }
inline Mask Eq(Vd a, Vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_EQ_OQ); }
inline Mask And(Mask a, Mask b) { return static_cast<Mask>(a & b); }
inline Mask Or(Mask a, Mask b) { return static_cast<Mask>(a | b); }
inline Mask AndNot(Mask a, Mask b) { return static_cast<Mask>(a & ~b); }  // a & ~b
inline Vd And(Vd v, Mask m) { return _mm512_maskz_mov_pd(m, v); }         // v where m, else +0
inline Vd AndNot(Vd v, Mask m) { return _mm512_maskz_mov_pd(static_cast<Mask>(~m), v); }
inline Vd AndNot(Vd a, Vd b) { return _mm512_andnot_pd(b, a); }              // a & ~b, bit by bit
inline Vd Sel(Mask m, Vd a, Vd b) { return _mm512_mask_blend_pd(m, b, a); }  // m ? a : b
inline Mask Sel(Mask m, Mask a, Mask b) { return static_cast<Mask>((m & a) | (~m & b)); }
inline int Bits(Mask m) { return m; }
// The first n < 8 lanes only (the others load as 0, are not stored; no access beyond them).
inline __mmask8 FirstLanes(int n) { return static_cast<__mmask8>((1u << n) - 1); }
inline Vd LoadN(const double* p, int n) { return _mm512_maskz_loadu_pd(FirstLanes(n), p); }
inline void StoreN(double* p, Vd v, int n) { _mm512_mask_storeu_pd(p, FirstLanes(n), v); }
#elif defined(__AVX__)
constexpr int kLanes = 4;
using Vd = __m256d;
using Mask = Vd;
inline Vd Splat(double x) { return _mm256_set1_pd(x); }
inline Vd Load(const double* p) { return _mm256_loadu_pd(p); }
inline void Store(double* p, Vd v) { _mm256_storeu_pd(p, v); }
inline Vd Lt(Vd a, Vd b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
inline Vd Le(Vd a, Vd b) { return _mm256_cmp_pd(a, b, _CMP_LE_OQ); }
inline Vd Ne(Vd a, Vd b) { return _mm256_cmp_pd(a, b, _CMP_NEQ_UQ); }
inline Vd Eq(Vd a, Vd b) { return _mm256_cmp_pd(a, b, _CMP_EQ_OQ); }
inline Vd And(Vd a, Vd b) { return _mm256_and_pd(a, b); }
inline Vd Or(Vd a, Vd b) { return _mm256_or_pd(a, b); }
inline Vd AndNot(Vd a, Vd b) { return _mm256_andnot_pd(b, a); }  // a & ~b
inline Vd Sel(Vd m, Vd a, Vd b) { return _mm256_blendv_pd(b, a, m); }
inline int Bits(Vd m) { return _mm256_movemask_pd(m); }
// The first n < 4 lanes only (the others load as 0, are not stored; no access beyond them).
inline __m256i FirstLanes(int n) {
  return _mm256_castpd_si256(_mm256_cmp_pd(_mm256_setr_pd(0, 1, 2, 3), Splat(n), _CMP_LT_OQ));
}
inline Vd LoadN(const double* p, int n) { return _mm256_maskload_pd(p, FirstLanes(n)); }
inline void StoreN(double* p, Vd v, int n) { _mm256_maskstore_pd(p, FirstLanes(n), v); }
#elif defined(__SSE2__)
constexpr int kLanes = 2;
using Vd = __m128d;
using Mask = Vd;
inline Vd Splat(double x) { return _mm_set1_pd(x); }
inline Vd Load(const double* p) { return _mm_loadu_pd(p); }
inline void Store(double* p, Vd v) { _mm_storeu_pd(p, v); }
inline Vd Lt(Vd a, Vd b) { return _mm_cmplt_pd(a, b); }
inline Vd Le(Vd a, Vd b) { return _mm_cmple_pd(a, b); }
inline Vd Ne(Vd a, Vd b) { return _mm_cmpneq_pd(a, b); }
inline Vd Eq(Vd a, Vd b) { return _mm_cmpeq_pd(a, b); }
inline Vd And(Vd a, Vd b) { return _mm_and_pd(a, b); }
inline Vd Or(Vd a, Vd b) { return _mm_or_pd(a, b); }
inline Vd AndNot(Vd a, Vd b) { return _mm_andnot_pd(b, a); }  // a & ~b
inline Vd Sel(Vd m, Vd a, Vd b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); }
inline int Bits(Vd m) { return _mm_movemask_pd(m); }
// The first lane only (n = 1; the other loads as 0, is not stored).
inline Vd LoadN(const double* p, int) { return _mm_load_sd(p); }
inline void StoreN(double* p, Vd v, int) { _mm_storel_pd(p, v); }
#else  // generic vectors (GCC / Clang extension)
constexpr int kLanes = 2;
using Vd = double __attribute__((vector_size(16)));
using Mask = Vd;
using Vi = long long __attribute__((vector_size(16)));
inline Vd Splat(double x) { return Vd{x, x}; }
inline Vd Load(const double* p) {
  Vd v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void Store(double* p, Vd v) { std::memcpy(p, &v, sizeof v); }
inline Vd Lt(Vd a, Vd b) { return reinterpret_cast<Vd>(a < b); }
inline Vd Le(Vd a, Vd b) { return reinterpret_cast<Vd>(a <= b); }
inline Vd Ne(Vd a, Vd b) { return reinterpret_cast<Vd>(a != b); }
inline Vd Eq(Vd a, Vd b) { return reinterpret_cast<Vd>(a == b); }
inline Vd Bit(Vi x) { return reinterpret_cast<Vd>(x); }
inline Vi Int(Vd x) { return reinterpret_cast<Vi>(x); }
inline Vd And(Vd a, Vd b) { return Bit(Int(a) & Int(b)); }
inline Vd Or(Vd a, Vd b) { return Bit(Int(a) | Int(b)); }
inline Vd AndNot(Vd a, Vd b) { return Bit(Int(a) & ~Int(b)); }
inline Vd Sel(Vd m, Vd a, Vd b) { return Or(And(m, a), AndNot(b, m)); }
inline int Bits(Vd m) { return (Int(m)[0] != 0 ? 1 : 0) | (Int(m)[1] != 0 ? 2 : 0); }
inline Vd LoadN(const double* p, int) { return Vd{p[0], 0}; }
inline void StoreN(double* p, Vd v, int) { p[0] = v[0]; }
#endif

#if !defined(RECRUIT_SMA_LANES8)
inline Vd ToVd(Mask m) { return m; }
inline Mask ToMask(Vd v) { return v; }
#endif

constexpr int kAll = (1 << kLanes) - 1;
inline Mask Gt(Vd a, Vd b) { return Lt(b, a); }
inline Mask Ge(Vd a, Vd b) { return Le(b, a); }
inline Mask Lt(Vd a, double b) { return Lt(a, Splat(b)); }
inline Mask Gt(Vd a, double b) { return Lt(Splat(b), a); }
inline Mask Le(Vd a, double b) { return Le(a, Splat(b)); }
inline Mask Ge(Vd a, double b) { return Le(Splat(b), a); }
inline Mask Eq(Vd a, double b) { return Eq(a, Splat(b)); }
// |x| by clearing the sign bit (std::abs).
inline Vd Abs(Vd x) { return AndNot(x, Splat(-0.0)); }
// std::clamp(v, 0, 1) lane by lane (NaN passes through, as there).
inline Vd Clamp01(Vd v) { return Sel(Lt(v, 0.0), Splat(0), Sel(Gt(v, 1.0), Splat(1), v)); }

// A major curve per lane: MajorHeating (t0 = As, t1 = Af) or MajorCooling (Mf, Ms), 1 at or
// below t0, 0 at or above t1, the cosine in between; slope as in the scalar overloads.
inline Vd MajorCurve(Vd te, Vd t0, Vd t1, Vd rate, Vd* slope) {
  const Mask below = Le(te, t0), above = Ge(te, t1), out = Or(below, above);
  Vd sn = Splat(0), cs = Splat(0);
  if (Bits(out) != kAll) SinCosHalfTurn(rate * (te - t0), &sn, &cs);
  *slope = AndNot((-0.5 * rate) * sn, out);
  return Sel(below, Splat(1), AndNot(0.5 * (cs + 1.0), above));
}

// The phase-solve constants of one model and extension, broadcast to every lane once.
struct Consts {
  bool rigid;         // no series spring
  Vd k_A, dk_w, k_s;  // k_A, k_M - k_A, series spring
  Vd k_s2_dk_w;       // k_s * k_s * (k_M - k_A), grouped as the scalar code evaluates it
  Vd stretch_L, stretch, latent, pn_h, pn_c;
  Vd As, Af, Ms, Mf, heat_rate, cool_rate;
};

inline Consts MakeConsts(const BatchParams& p, double stretch) {
  Consts k;
  k.rigid = p.k_s <= 0;
  k.k_A = Splat(p.k_A);
  k.dk_w = Splat(p.k_M - p.k_A);
  k.k_s = Splat(p.k_s);
  k.k_s2_dk_w = Splat(p.k_s * p.k_s * (p.k_M - p.k_A));
  k.stretch_L = Splat(p.stretch_L);
  k.stretch = Splat(stretch);
  k.latent = Splat(p.latent);
  k.pn_h = Splat(p.pn_h);
  k.pn_c = Splat(p.pn_c);
  k.As = Splat(p.As);
  k.Af = Splat(p.Af);
  k.Ms = Splat(p.Ms);
  k.Mf = Splat(p.Mf);
  k.heat_rate = Splat(p.heat_rate);
  k.cool_rate = Splat(p.cool_rate);
  return k;
}

// UnitModel::Tension(x, stretch, &slope) lane by lane.
inline Vd LaneTension(const Consts& c, Vd xi, Vd* slope) {
  const Vd kw = c.k_A + xi * c.dk_w;
  Vd k, dk;
  if (c.rigid) {
    dk = c.dk_w;
    k = kw;
  } else {
    const Vd inv = 1.0 / (kw + c.k_s);
    dk = c.k_s2_dk_w * inv * inv;
    k = kw * c.k_s * inv;
  }
  const Vd e = c.stretch - xi * c.stretch_L;
  const Vd ke = k * e;
  const Mask slack = Le(ke, 0.0);
  *slope = AndNot(dk * e - k * c.stretch_L, slack);
  return AndNot(ke, slack);
}

// UnitModel::Tension(x, stretch) lane by lane: std::max(0.0, k e).
inline Vd TensionOnly(const Consts& c, Vd xi) {
  const Vd kw = c.k_A + xi * c.dk_w;
  const Vd k = c.rigid ? kw : kw * c.k_s * (1.0 / (kw + c.k_s));
  const Vd ke = k * (c.stretch - xi * c.stretch_L);
  return And(ke, Gt(ke, 0.0));
}

// Per-lane inputs of a phase solve; heat selects gd_h (M -> A on M+) or gd_c (A -> M on M-).
struct Lanes {
  Mask heat;
  Vd xi0, tth, hs, cs, pn, scale, t0, t1, rate;
};

// gd_h / gd_c of SolvePhase: residual g and its slope dg at x.
inline void Residual(const Consts& c, const Lanes& L, Vd x, Vd* g, Vd* dg) {
  Vd dfdx, slope;
  const Vd te = (L.tth + c.latent * (x - L.xi0)) - L.pn * LaneTension(c, x, &dfdx);
  const Vd mv = MajorCurve(te, L.t0, L.t1, L.rate, &slope);
  *g = Sel(L.heat, x - L.hs * mv, x - 1.0 + L.cs * (1.0 - mv));
  *dg = 1.0 - L.scale * slope * (c.latent - L.pn * dfdx);
}

// SolveNewton lane by lane from x = xi_n, where the residual is g, dg: heating on [0, xi_n],
// cooling on [xi_n, 1].
// One batch's Newton state; a lane whose `active` bit is clear keeps its values.
struct NewtonLanes {
  Vd lo, hi, x, g, dg;
  Mask active;
};

inline NewtonLanes NewtonStart(const Lanes& L, Vd g, Vd dg) {
  NewtonLanes s;
  s.lo = AndNot(L.xi0, L.heat);
  s.hi = Sel(L.heat, L.xi0, Splat(1));
  s.x = L.xi0;
  s.g = g;
  s.dg = dg;
  s.active = Or(Le(s.x, s.x), Ne(s.x, s.x));  // every lane
  return s;
}

// Every lane's mask (the comparison's all-ones result).
inline Mask AllLanes() {
  const Vd z = Splat(0);
  return Le(z, z);
}

// The mask of lanes 0 .. count - 1.
inline Mask ValidLanes(int count) {
  alignas(64) static constexpr double kIndex[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  return Lt(Load(kIndex), Splat(count));
}

// The bracket update and the Newton (or bisection) step of the active lanes.
inline void NewtonStep(NewtonLanes& s) {
  const Mask pos = Gt(s.g, 0.0);
  s.hi = Sel(And(s.active, pos), s.x, s.hi);
  s.lo = Sel(AndNot(s.active, pos), s.x, s.lo);
  const Vd mid = 0.5 * (s.lo + s.hi);
  Vd next = Sel(Gt(s.dg, 0.0), s.x - s.g / s.dg, mid);
  next = Sel(And(Gt(next, s.lo), Lt(next, s.hi)), next, mid);
  const Vd step = next - s.x;
  s.x = Sel(s.active, next, s.x);
  s.active = AndNot(s.active, Or(Lt(Abs(step), 1e-10), Lt(s.hi - s.lo, 1e-15)));
}

// The residual at the new x of the lanes still active.
inline void NewtonResidual(const Consts& c, const Lanes& L, NewtonLanes& s) {
  Vd gn, dgn;
  Residual(c, L, s.x, &gn, &dgn);
  s.g = Sel(s.active, gn, s.g);
  s.dg = Sel(s.active, dgn, s.dg);
  s.active = AndNot(s.active, Lt(Abs(s.g), 1e-13));
}

// Lanes outside `solving` start stopped: they keep x = xi_n, and the loop ends with the others.
inline Vd Newton(const Consts& c, const Lanes& L, Vd g, Vd dg, Mask solving = AllLanes()) {
  NewtonLanes s = NewtonStart(L, g, dg);
  s.active = solving;
  for (int it = 0; it < 60; ++it) {
    NewtonStep(s);
    if (Bits(s.active) == 0) break;
    NewtonResidual(c, L, s);
    if (Bits(s.active) == 0) break;
  }
  return s.x;
}

// Two batches in one loop, so that their dependency chains (division, polynomial, division)
// overlap: lane by lane the same iterations as Newton, since a lane that has stopped keeps its
// values while the other batch's lanes go on.
inline void Newton2(const Consts& c, const Lanes& La, const Lanes& Lb, Vd ga, Vd dga, Vd gb, Vd dgb,
                    Vd* xa, Vd* xb) {
  NewtonLanes a = NewtonStart(La, ga, dga), b = NewtonStart(Lb, gb, dgb);
  for (int it = 0; it < 60; ++it) {
    NewtonStep(a);
    NewtonStep(b);
    const int live_a = Bits(a.active), live_b = Bits(b.active);
    if ((live_a | live_b) == 0) break;
    // A batch whose lanes have all stopped keeps its values: its residual would be discarded.
    if (live_a != 0) NewtonResidual(c, La, a);
    if (live_b != 0) NewtonResidual(c, Lb, b);
    if ((Bits(a.active) | Bits(b.active)) == 0) break;
  }
  *xa = a.x;
  *xb = b.x;
}

// Canonical ends of the loop (SolvePhase), so that settled cohorts compare equal.
inline void Canonical(Vd* xi, Vd* hs, Vd* cs) {
  const Mask top = Ge(*xi, 1 - 1e-12), bottom = Le(*xi, 1e-12);
  if (Bits(Or(top, bottom)) == 0) return;
  const Mask low = AndNot(bottom, top);
  *xi = Sel(top, Splat(1), AndNot(*xi, low));
  *hs = Sel(top, Splat(1), AndNot(*hs, low));
  *cs = Sel(top, Splat(0), Sel(low, Splat(1), *cs));
}

// Appending the lanes a mask selects, lowest first, without a loop over its bits:
// AppendLanes appends base + l for each set bit l of `bits` to list[n..] and returns the new
// length; AppendValues appends those lanes of v to list[n..]. Both write kLanes entries.
#if defined(RECRUIT_SMA_LANES8)
inline int AppendLanes(int* list, int n, int base, int bits) {
  const __m512i lanes = _mm512_add_epi32(
      _mm512_set1_epi32(base), _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 0, 0, 0, 0, 0, 0, 0));
  // A masked store of the low 8 (GCC 12 warns on the intrinsics that take the low half).
  _mm512_mask_storeu_epi32(list + n, 0xff,
                           _mm512_maskz_compress_epi32(static_cast<__mmask16>(bits), lanes));
  return n + __builtin_popcount(bits);
}
inline void AppendValues(double* list, int n, Vd v, int bits) {
  Store(list + n, _mm512_maskz_compress_pd(static_cast<Mask>(bits), v));
}
#else
// Each lane mask's set lanes, lowest first, how many, and (AVX2) the 32-bit halves of those
// lanes (a permutation of 8 floats that moves them to the front).
struct LaneLists {
  int lane[1 << kLanes][kLanes];
  int count[1 << kLanes];
  int halves[1 << kLanes][2 * kLanes];
};
constexpr LaneLists MakeLaneLists() {
  LaneLists t{};
  for (int m = 0; m < (1 << kLanes); ++m) {
    for (int l = 0; l < kLanes; ++l) {
      if ((m >> l) & 1) t.lane[m][t.count[m]++] = l;
    }
    for (int l = 0; l < kLanes; ++l) {
      t.halves[m][2 * l] = 2 * t.lane[m][l];
      t.halves[m][2 * l + 1] = 2 * t.lane[m][l] + 1;
    }
  }
  return t;
}
constexpr LaneLists kLaneLists = MakeLaneLists();

inline int AppendLanes(int* list, int n, int base, int bits) {
  for (int l = 0; l < kLanes; ++l) list[n + l] = base + kLaneLists.lane[bits][l];
  return n + kLaneLists.count[bits];
}
inline void AppendValues(double* list, int n, Vd v, int bits) {
#if defined(__AVX2__)
  const __m256i perm =
      _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kLaneLists.halves[bits]));
  Store(list + n, _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(v), perm)));
#else
  alignas(32) double lanes[kLanes];
  Store(lanes, v);
  for (int l = 0; l < kLanes; ++l) list[n + l] = lanes[kLaneLists.lane[bits][l]];
#endif
}
#endif

// kLanes consecutive cohorts' fields in the caller's arrays (the tail: fewer, masked).
struct Block {
  const double* on;
  double *temperature, *xi, *t_eff, *heat_scale, *cool_scale;
};

// The block of cohorts from cohort `first` on.
inline Block BlockAt(const BatchCohorts& c, int first) {
  return {c.on + first,    c.temperature + first, c.xi + first,
          c.t_eff + first, c.heat_scale + first,  c.cool_scale + first};
}

// The thermal step and the constants of the update, broadcast to every lane.
struct StepConsts {
  Consts k;
  Vd amb, rise_A, rise_dM, decay;
};

inline StepConsts MakeStepConsts(const BatchParams& p, double stretch, double decay) {
  return {MakeConsts(p, stretch), Splat(p.ambient), Splat(p.rise_A), Splat(p.rise_dM),
          Splat(decay)};
}

// (A) for one block of cohorts: the thermal step, the branch, the residual at xi_n, whether
// the cohort transforms, and its values if it does not.
struct PhaseA {
  Vd xi0, hs0, cs0, T0, t_th, te0, g, dg;
  Mask is_heat, tr;
  Vd x, h, cl;  // xi, heat_scale, cool_scale of a cohort that does not transform
};

__attribute__((always_inline)) inline PhaseA ThermalStepAndTest(const StepConsts& sc, Vd on, Vd T0,
                                                                Vd xi0, Vd te_prev, Vd hs0,
                                                                Vd cs0) {
  const Consts& k = sc.k;
  PhaseA a;
  a.xi0 = xi0, a.hs0 = hs0, a.cs0 = cs0, a.T0 = T0;
  const Vd t_ss = Sel(Ne(on, Splat(0)), sc.amb + (sc.rise_A + xi0 * sc.rise_dM), sc.amb);
  a.t_th = t_ss + (T0 - t_ss) * sc.decay;
  Vd dfdx0;
  const Vd f0 = LaneTension(k, xi0, &dfdx0);
  const Vd te_h0 = a.t_th - k.pn_h * f0;
  a.is_heat = Ge(te_h0, te_prev);
  a.te0 = Sel(a.is_heat, te_h0, a.t_th - k.pn_c * f0);
  const Vd pn = Sel(a.is_heat, k.pn_h, k.pn_c);
  Vd slope;
  const Vd mv = MajorCurve(a.te0, Sel(a.is_heat, k.As, k.Mf), Sel(a.is_heat, k.Af, k.Ms),
                           Sel(a.is_heat, k.heat_rate, k.cool_rate), &slope);
  a.g = Sel(a.is_heat, xi0 - hs0 * mv, xi0 - 1.0 + cs0 * (1.0 - mv));
  a.dg = 1.0 - Sel(a.is_heat, hs0, cs0) * slope * (k.latent - pn * dfdx0);
  a.tr = Sel(a.is_heat, Gt(a.g, 1e-12), Lt(a.g, -1e-12));
  a.x = xi0, a.h = hs0, a.cl = cs0;
  Canonical(&a.x, &a.h, &a.cl);
  return a;
}

// A block's first `count` lanes: all kLanes as full vectors, fewer (the tail) masked, with no
// access beyond them (the other lanes load as 0 and are not stored).
inline Vd LoadLanes(const double* p, int count) {
  return count == kLanes ? Load(p) : LoadN(p, count);
}
inline void StoreLanes(double* p, Vd v, int count) {
  if (count == kLanes) {
    Store(p, v);
  } else {
    StoreN(p, v, count);
  }
}

// ThermalStepAndTest of a block's `count` cohorts.
__attribute__((always_inline)) inline PhaseA BlockStepAndTest(const StepConsts& sc, const Block& b,
                                                              int count) {
  return ThermalStepAndTest(sc, LoadLanes(b.on, count), LoadLanes(b.temperature, count),
                            LoadLanes(b.xi, count), LoadLanes(b.t_eff, count),
                            LoadLanes(b.heat_scale, count), LoadLanes(b.cool_scale, count));
}

// The per-lane inputs of a solve from xi_n, T after the thermal step, the scales and the branch.
__attribute__((always_inline)) inline Lanes MakeLanes(const Consts& k, Mask heat, Vd xi0, Vd tth,
                                                      Vd hs, Vd cs) {
  Lanes L;
  L.heat = heat;
  L.xi0 = xi0;
  L.tth = tth;
  L.hs = hs;
  L.cs = cs;
  L.pn = Sel(L.heat, k.pn_h, k.pn_c);
  L.scale = Sel(L.heat, L.hs, L.cs);
  L.t0 = Sel(L.heat, k.As, k.Mf);
  L.t1 = Sel(L.heat, k.Af, k.Ms);
  L.rate = Sel(L.heat, k.heat_rate, k.cool_rate);
  return L;
}

// A solved cohort's new fields.
struct Solved {
  Vd T, xi, t_eff, hs, cs;
};

__attribute__((always_inline)) inline Solved FinishSolve(const Consts& k, const Lanes& L, Vd x) {
  // T_eff at the solution; the opposite branch's scale restarts there (proportional rule).
  const Vd t_eff = (L.tth + k.latent * (x - L.xi0)) - L.pn * TensionOnly(k, x);
  Vd unused;
  const Vd other = MajorCurve(t_eff, Sel(L.heat, k.Mf, k.As), Sel(L.heat, k.Ms, k.Af),
                              Sel(L.heat, k.cool_rate, k.heat_rate), &unused);
  // Heating: cool_scale = (1 - x) / (1 - M-); cooling: heat_scale = x / M+ (one division).
  const Vd ratio = Clamp01(Sel(L.heat, 1.0 - x, x) / Sel(L.heat, 1.0 - other, other));
  Vd cl = Sel(L.heat, Sel(Lt(other, 1.0), ratio, Splat(1)), L.cs);
  Vd h = Sel(L.heat, L.hs, Sel(Gt(other, 0.0), ratio, Splat(1)));
  Canonical(&x, &h, &cl);
  return {L.tth + k.latent * (x - L.xi0), x, t_eff, h, cl};
}

// The telemetry of one block's `count` updated cohorts (BatchObserve) from the update's
// registers. The same products as ObservePass's (count times on, temperature, xi and the tension
// at obs->stretch), each added to +0 like the first of its partial sum there, the lanes past
// `count` +0 (ObservePass's masked tail adds +0, which changes no sum: none is -0), lanes l and
// l + 4 of an 8-lane block added into partial sum l as ObservePass adds cohorts l and l + 4, and
// the partial sums added as (s0 + s1) + (s2 + s3): bit for bit SumTelemetry's values, whose few-
// cohort scalar path keeps the same four partial sums. The maxima do not depend on the order
// (no value is NaN; a tension is never -0).
inline void ObserveBlock(const BatchParams& p, BatchObserve* obs, Vd on, Vd T, Vd xi, int count) {
  const Consts kt = MakeConsts(p, obs->stretch);
  const Mask valid = ValidLanes(count);
  const Vd c = LoadLanes(obs->count, count);
#if defined(__AVX__) && !defined(RECRUIT_SMA_LANES8)
  // Four lanes, one per partial sum: in registers, (a0 + a1) + (a2 + a3) by a horizontal add
  // (two fields' a0 + a1 low, a2 + a3 high) and an add of the halves, as ObservePass does.
  {
    const Vd t = And(TensionOnly(kt, xi), valid);
    const Vd a0 = Splat(0) + And(c * on, valid), a1 = Splat(0) + And(c * T, valid);
    const Vd a2 = Splat(0) + And(c * xi, valid), a3 = Splat(0) + c * t;
    const __m256d h01 = _mm256_hadd_pd(a0, a1), h23 = _mm256_hadd_pd(a2, a3);
    _mm_storeu_pd(obs->out, _mm_add_pd(_mm256_castpd256_pd128(h01), _mm256_extractf128_pd(h01, 1)));
    _mm_storeu_pd(obs->out + 2,
                  _mm_add_pd(_mm256_castpd256_pd128(h23), _mm256_extractf128_pd(h23, 1)));
    // Maxima: lanes swapped in pairs, then halves (no value is NaN: the order does not matter).
    const Vd hot = Sel(valid, T, Splat(-HUGE_VAL));
    Vd mt = _mm256_max_pd(t, _mm256_permute_pd(t, 5));
    Vd mh = _mm256_max_pd(hot, _mm256_permute_pd(hot, 5));
    mt = _mm256_max_pd(mt, _mm256_permute2f128_pd(mt, mt, 1));
    mh = _mm256_max_pd(mh, _mm256_permute2f128_pd(mh, mh, 1));
    obs->out[4] = _mm256_cvtsd_f64(mt);
    obs->out[5] = _mm256_cvtsd_f64(mh);
    obs->done = true;
    return;
  }
#endif
  alignas(64) double a[4][8] = {}, top[8], hot[8];
  Store(a[0], Splat(0) + And(c * on, valid));
  Store(a[1], Splat(0) + And(c * T, valid));
  Store(a[2], Splat(0) + And(c * xi, valid));
  const Vd t = And(TensionOnly(kt, xi), valid);
  Store(a[3], Splat(0) + c * t);
  Store(top, t);
  Store(hot, Sel(valid, T, Splat(-HUGE_VAL)));
  for (int f = 0; f < 4; ++f) {
    double q[4] = {a[f][0], a[f][1], a[f][2], a[f][3]};
    for (int l = 4; l < kLanes; ++l) q[l - 4] = q[l - 4] + a[f][l];
    obs->out[f] = (q[0] + q[1]) + (q[2] + q[3]);
  }
  double peak = 0, hottest = hot[0];
  for (int l = 0; l < kLanes; ++l) {
    peak = top[l] > peak ? top[l] : peak;
    hottest = hot[l] > hottest ? hot[l] : hottest;
  }
  obs->out[4] = peak;
  obs->out[5] = hottest;
  obs->done = true;
}

// The update of one block's `count` cohorts: phase A's values stay in registers and the
// transforming lanes are solved where they are, the others stopped, without the gather through
// memory that batches many cohorts. Lane by lane the same operations. The new fields are stored
// and returned.
__attribute__((always_inline)) inline Solved UpdateBlock(const StepConsts& sc, const Block& b,
                                                         int count) {
  const PhaseA a = BlockStepAndTest(sc, b, count);
  Solved out{a.t_th + sc.k.latent * (a.x - a.xi0), a.x, a.te0, a.h, a.cl};
  // The lanes past `count` hold zeros: they must not keep the solve going.
  const Mask tr = And(a.tr, ValidLanes(count));
  if (Bits(tr) != 0) {
    const Lanes L = MakeLanes(sc.k, a.is_heat, a.xi0, a.t_th, a.hs0, a.cs0);
    const Solved s = FinishSolve(sc.k, L, Newton(sc.k, L, a.g, a.dg, tr));
    out = {Sel(tr, s.T, out.T), Sel(tr, s.xi, out.xi), Sel(tr, s.t_eff, out.t_eff),
           Sel(tr, s.hs, out.hs), Sel(tr, s.cs, out.cs)};
  }
  StoreLanes(b.temperature, out.T, count);
  StoreLanes(b.xi, out.xi, count);
  StoreLanes(b.t_eff, out.t_eff, count);
  StoreLanes(b.heat_scale, out.hs, count);
  StoreLanes(b.cool_scale, out.cs, count);
  return out;
}

// All n <= kLanes cohorts in one block (an arm's bundle has about four).
inline void AdvanceOneBlock(const StepConsts& sc, const BatchParams& p, BatchObserve* obs,
                            const Block& b, int count) {
  const Solved out = UpdateBlock(sc, b, count);
  if (obs != nullptr) ObserveBlock(p, obs, LoadLanes(b.on, count), out.T, out.xi, count);
}

// The telemetry of two blocks' n (kLanes < n <= 2 kLanes) updated cohorts, block a full and b's
// first n - kLanes lanes real (BatchObserve), bit for bit SumTelemetry's values as ObserveBlock's:
// ObservePass adds cohorts l and l + 4 into partial sum l (with four lanes: lane l of a, then lane
// l of b; with two: cohorts 0..3 are the partial sums themselves, b's lanes the last two), each
// product added to +0 first (so that none is -0; b's masked lanes add +0, which changes no sum).
inline void ObserveTwoBlocks(const BatchParams& p, BatchObserve* obs, Vd on_a, Vd T_a, Vd xi_a,
                             Vd on_b, Vd T_b, Vd xi_b, int count_b) {
  const Consts kt = MakeConsts(p, obs->stretch);
  const Mask valid = ValidLanes(count_b);
  const Vd c_a = Load(obs->count), c_b = LoadLanes(obs->count + kLanes, count_b);
  const Vd t_a = TensionOnly(kt, xi_a), t_b = And(TensionOnly(kt, xi_b), valid);
  const Vd z = Splat(0);
#if defined(__AVX__) && !defined(RECRUIT_SMA_LANES8)
  // Partial sum l = (+0 + a's lane l) + (+0 + b's lane l), then (s0 + s1) + (s2 + s3) by a
  // horizontal add and an add of the halves, as ObserveBlock.
  const Vd s0 = (z + c_a * on_a) + (z + And(c_b * on_b, valid));
  const Vd s1 = (z + c_a * T_a) + (z + And(c_b * T_b, valid));
  const Vd s2 = (z + c_a * xi_a) + (z + And(c_b * xi_b, valid));
  const Vd s3 = (z + c_a * t_a) + (z + c_b * t_b);
  const __m256d h01 = _mm256_hadd_pd(s0, s1), h23 = _mm256_hadd_pd(s2, s3);
  _mm_storeu_pd(obs->out, _mm_add_pd(_mm256_castpd256_pd128(h01), _mm256_extractf128_pd(h01, 1)));
  _mm_storeu_pd(obs->out + 2,
                _mm_add_pd(_mm256_castpd256_pd128(h23), _mm256_extractf128_pd(h23, 1)));
  // Maxima (no value is NaN, a tension is never -0: the order does not matter).
  Vd mt = _mm256_max_pd(t_a, t_b);
  Vd mh = _mm256_max_pd(T_a, Sel(valid, T_b, Splat(-HUGE_VAL)));
  mt = _mm256_max_pd(mt, _mm256_permute_pd(mt, 5));
  mh = _mm256_max_pd(mh, _mm256_permute_pd(mh, 5));
  mt = _mm256_max_pd(mt, _mm256_permute2f128_pd(mt, mt, 1));
  mh = _mm256_max_pd(mh, _mm256_permute2f128_pd(mh, mh, 1));
  obs->out[4] = _mm256_cvtsd_f64(mt);
  obs->out[5] = _mm256_cvtsd_f64(mh);
#else
  // Cohort j's products in a[f][j] (b's masked lanes +0), folded as ObservePass adds them.
  alignas(64) double a[4][2 * kLanes], top[2 * kLanes], hot[2 * kLanes];
  Store(a[0], z + c_a * on_a);
  Store(a[0] + kLanes, z + And(c_b * on_b, valid));
  Store(a[1], z + c_a * T_a);
  Store(a[1] + kLanes, z + And(c_b * T_b, valid));
  Store(a[2], z + c_a * xi_a);
  Store(a[2] + kLanes, z + And(c_b * xi_b, valid));
  Store(a[3], z + c_a * t_a);
  Store(a[3] + kLanes, z + c_b * t_b);
  Store(top, t_a);
  Store(top + kLanes, t_b);
  Store(hot, T_a);
  Store(hot + kLanes, Sel(valid, T_b, Splat(-HUGE_VAL)));
  for (int f = 0; f < 4; ++f) {
    double q[4] = {0, 0, 0, 0};
    for (int l = 0; l < 2 * kLanes; ++l) q[l % 4] = l < 4 ? a[f][l] : q[l % 4] + a[f][l];
    obs->out[f] = (q[0] + q[1]) + (q[2] + q[3]);
  }
  double peak = 0, hottest = hot[0];
  for (int l = 0; l < 2 * kLanes; ++l) {
    peak = top[l] > peak ? top[l] : peak;
    hottest = hot[l] > hottest ? hot[l] : hottest;
  }
  obs->out[4] = peak;
  obs->out[5] = hottest;
#endif
  obs->done = true;
}

// kLanes < n <= 2 kLanes cohorts (5-8 with AVX2: a bundle switched a few units at a time keeps
// that many): each block updated as one block is (UpdateBlock: phase A's values in registers, the
// transforming lanes solved where they are), without the two-phase path's stores, gathers and
// scatters, and the telemetry from the registers that hold both blocks' new fields. Lane by lane
// the same operations. (Both blocks' phase A at once and the solves of both through Newton2 kept
// too many values live for the registers: it cost more than the two-phase path.)
inline void AdvanceTwoBlocks(const StepConsts& sc, const BatchParams& p, BatchObserve* obs,
                             const Block& ba, const Block& bb, int count_b) {
  const Solved a = UpdateBlock(sc, ba, kLanes);
  const Solved b = UpdateBlock(sc, bb, count_b);
#if !defined(RECRUIT_SMA_LANES8)
  // (The 8-lane update is given no `obs`: UnitModel::Update.)
  if (obs != nullptr) {
    ObserveTwoBlocks(p, obs, Load(ba.on), a.T, a.xi, LoadLanes(bb.on, count_b), b.T, b.xi, count_b);
  }
#else
  (void)p;
  (void)obs;
  (void)a;
  (void)b;
#endif
}

#pragma GCC diagnostic pop

}  // namespace

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// Cohorts in chunks of 64: (A) the thermal step, the branch test and the residual at xi_n for
// all, kLanes at a time; cohorts that do not transform are finished there. (B) The phase solves
// of those that do, gathered kLanes at a time.
void AdvanceCohorts(const BatchParams& p, const BatchCohorts& c, int n, double stretch,
                    double decay, BatchObserve* obs) {
  constexpr int kChunk = 64;
  const StepConsts sc = MakeStepConsts(p, stretch, decay);
  const Consts& k = sc.k;
  if (n <= kLanes) {
    if (n > 0) {
      AdvanceOneBlock(sc, p, obs, BlockAt(c, 0), n);
    }
    return;
  }
  if (n <= 2 * kLanes) {
    AdvanceTwoBlocks(sc, p, obs, BlockAt(c, 0), BlockAt(c, kLanes), n - kLanes);
    return;
  }
  alignas(32) double tth[kChunk], g0[kChunk], dg0[kChunk], heat[kChunk];
  int solve[kChunk + kLanes];
  for (int base = 0; base < n; base += kChunk) {
    const int m = n - base < kChunk ? n - base : kChunk;
    int n_solve = 0;
    // (A) on cohorts base + j .. base + j + kLanes - 1; `valid` has the bits of real lanes.
    // The block's `count` lanes are real cohorts (kLanes but at the tail); others are zeros.
    auto phase_a = [&](const Block& b, int j, int count) __attribute__((always_inline)) {
      const PhaseA a = BlockStepAndTest(sc, b, count);
      // Cohorts that do not transform keep xi_n and are finished here; the others keep their
      // old values until (B).
      StoreLanes(b.temperature, Sel(a.tr, a.T0, a.t_th + k.latent * (a.x - a.xi0)), count);
      StoreLanes(b.xi, Sel(a.tr, a.xi0, a.x), count);
      StoreLanes(b.t_eff, a.te0, count);
      StoreLanes(b.heat_scale, Sel(a.tr, a.hs0, a.h), count);
      StoreLanes(b.cool_scale, Sel(a.tr, a.cs0, a.cl), count);
      Store(tth + j, a.t_th);
      Store(g0 + j, a.g);
      Store(dg0 + j, a.dg);
      Store(heat + j, ToVd(a.is_heat));
      n_solve = AppendLanes(solve, n_solve, j, Bits(a.tr) & ((1 << count) - 1));
    };
    const double* const on = c.on + base;
    double* const T = c.temperature + base;
    double* const xi = c.xi + base;
    double* const te = c.t_eff + base;
    double* const hs = c.heat_scale + base;
    double* const cs = c.cool_scale + base;
    int j = 0;
    for (; j + kLanes <= m; j += kLanes) {
      phase_a(Block{on + j, T + j, xi + j, te + j, hs + j, cs + j}, j, kLanes);
    }
    if (j < m) phase_a(Block{on + j, T + j, xi + j, te + j, hs + j, cs + j}, j, m - j);
    // (B) A short batch repeats its last cohort (same inputs, same result). Batches go through
    // Newton in pairs (their cohorts differ: both are read before either is written).
    if (n_solve % kLanes != 0) {
      const int last = solve[n_solve - 1];
      for (int l = 0; l < kLanes; ++l) solve[n_solve + l] = last;  // one store
    }
    auto prepare = [&](const int* idx, Lanes* L, Vd* g, Vd* dg) __attribute__((always_inline)) {
      // Lane-by-lane loads (faster here than the gather instructions).
#if defined(RECRUIT_SMA_LANES8)
      auto gather = [&](const double* a) {
        return _mm512_setr_pd(a[idx[0]], a[idx[1]], a[idx[2]], a[idx[3]], a[idx[4]], a[idx[5]],
                              a[idx[6]], a[idx[7]]);
      };
#elif defined(__AVX__)
      auto gather = [&](const double* a) {
        return _mm256_setr_pd(a[idx[0]], a[idx[1]], a[idx[2]], a[idx[3]]);
      };
#elif defined(__SSE2__)
      auto gather = [&](const double* a) { return _mm_setr_pd(a[idx[0]], a[idx[1]]); };
#else
      auto gather = [&](const double* a) { return Vd{a[idx[0]], a[idx[1]]}; };
#endif
      *L = MakeLanes(k, ToMask(gather(heat)), gather(xi), gather(tth), gather(hs), gather(cs));
      *g = gather(g0);
      *dg = gather(dg0);
    };
    auto finish = [&](const int* idx, const Lanes& L, Vd x) __attribute__((always_inline)) {
      const Solved s = FinishSolve(k, L, x);
      alignas(64) double out[5][kLanes];
      Store(out[0], s.T);
      Store(out[1], s.xi);
      Store(out[2], s.t_eff);
      Store(out[3], s.hs);
      Store(out[4], s.cs);
      for (int l = 0; l < kLanes; ++l) {
        const int i = idx[l];
        T[i] = out[0][l];
        xi[i] = out[1][l];
        te[i] = out[2][l];
        hs[i] = out[3][l];
        cs[i] = out[4][l];
      }
    };
    int b = 0;
    for (; b + kLanes < n_solve; b += 2 * kLanes) {
      Lanes La, Lb;
      Vd ga, dga, gb, dgb, xa, xb;
      prepare(solve + b, &La, &ga, &dga);
      prepare(solve + b + kLanes, &Lb, &gb, &dgb);
      Newton2(k, La, Lb, ga, dga, gb, dgb, &xa, &xb);
      finish(solve + b, La, xa);
      finish(solve + b + kLanes, Lb, xb);
    }
    if (b < n_solve) {
      Lanes L;
      Vd g, dg;
      prepare(solve + b, &L, &g, &dg);
      finish(solve + b, L, Newton(k, L, g, dg));
    }
  }
}

// The sums keep four partial sums (lane j mod 4), so the 8-lane clone has none of them.
#ifndef RECRUIT_SMA_LANES8
void AdvanceBlockBeforeUpdatedTail(const BatchParams& p, const BatchCohorts& c, int n,
                                   double stretch, double decay, BatchObserve* obs) {
  const StepConsts sc = MakeStepConsts(p, stretch, decay);
  const Solved a = UpdateBlock(sc, BlockAt(c, 0), kLanes);
  if (obs == nullptr) return;
  const int rest = n - kLanes;  // updated by the caller
  ObserveTwoBlocks(p, obs, Load(c.on), a.T, a.xi, LoadLanes(c.on + kLanes, rest),
                   LoadLanes(c.temperature + kLanes, rest), LoadLanes(c.xi + kLanes, rest), rest);
}

double SumTension(const BatchParams& p, const double* count, const double* xi, int n,
                  double stretch) {
  // Four partial sums (cohort j mod 4; one register with AVX, two with SSE2), added as
  // (s0 + s1) + (s2 + s3): the same value in both clones.
  constexpr int kRegs = 4 / kLanes;
  const Consts k = MakeConsts(p, stretch);
  Vd acc[kRegs];
  for (int r = 0; r < kRegs; ++r) acc[r] = Splat(0);
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    for (int r = 0; r < kRegs; ++r) {
      const int i = j + r * kLanes;
      acc[r] += Load(count + i) * TensionOnly(k, Load(xi + i));
    }
  }
  alignas(32) double a[4];
  for (int r = 0; r < kRegs; ++r) Store(a + r * kLanes, acc[r]);
  // The last n - j < 4 cohorts: masked loads (missing lanes are 0: count 0, xi 0, term +0).
  for (int r = 0; r < kRegs && j + r * kLanes < n; ++r) {
    const int i = j + r * kLanes, rest = n - i;
    const Vd cnt = rest >= kLanes ? Load(count + i) : LoadN(count + i, rest);
    const Vd x = rest >= kLanes ? Load(xi + i) : LoadN(xi + i, rest);
    alignas(32) double f[kLanes];
    Store(f, cnt * TensionOnly(k, x));
    for (int l = 0; l < kLanes; ++l) a[r * kLanes + l] += f[l];
  }
  return (a[0] + a[1]) + (a[2] + a[3]);
}

namespace {

// max(a, b) lane by lane for values that are never NaN (tensions: >= +0), where the order of
// the comparisons cannot change the result.
inline Vd MaxOf(Vd a, Vd b) { return Sel(Gt(a, b), a, b); }

// SumTelemetry with or without the largest tension (the sensor needs only the sums).
template <bool kPeak>
void ObservePass(const BatchParams& p, const double* count, const double* const* v, int n,
                 double stretch, double* out) {
  constexpr int kRegs = 4 / kLanes;
  const Consts k = MakeConsts(p, stretch);
  Vd acc[4][kRegs], peak[kRegs];
  for (int r = 0; r < kRegs; ++r) {
    for (int f = 0; f < 4; ++f) acc[f][r] = Splat(0);
    peak[r] = Splat(0);
  }
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    for (int r = 0; r < kRegs; ++r) {
      const int i = j + r * kLanes;
      const Vd c = Load(count + i), x = Load(v[2] + i), t = TensionOnly(k, x);
      acc[0][r] += c * Load(v[0] + i);
      acc[1][r] += c * Load(v[1] + i);
      acc[2][r] += c * x;
      acc[3][r] += c * t;
      if (kPeak) peak[r] = MaxOf(t, peak[r]);
    }
  }
  // The last n - j < 4 cohorts from masked loads, as SumTension: a missing lane adds count 0
  // times 0 (or a tension), +0, which leaves a partial sum as it is (from +0, never -0).
  double top_tail = 0;
  for (int r = 0; r < kRegs && j + r * kLanes < n; ++r) {
    const int i = j + r * kLanes, rest = n - i;
    auto load = [&](const double* a) { return rest >= kLanes ? Load(a + i) : LoadN(a + i, rest); };
    const Vd c = load(count), x = load(v[2]), t = TensionOnly(k, x);
    acc[0][r] += c * load(v[0]);
    acc[1][r] += c * load(v[1]);
    acc[2][r] += c * x;
    acc[3][r] += c * t;
    if (kPeak) {
      alignas(32) double tl[kLanes];
      Store(tl, t);
      for (int l = 0; l < kLanes && l < rest; ++l) top_tail = tl[l] > top_tail ? tl[l] : top_tail;
    }
  }
  // out[f] = (a0 + a1) + (a2 + a3) of field f's partial sums.
#if defined(__AVX__)
  // In registers: hadd gives two fields' a0 + a1 in its low half and a2 + a3 in its high half.
  for (int f = 0; f < 4; f += 2) {
    const __m256d h = _mm256_hadd_pd(acc[f][0], acc[f + 1][0]);
    _mm_storeu_pd(out + f, _mm_add_pd(_mm256_castpd256_pd128(h), _mm256_extractf128_pd(h, 1)));
  }
#else
  alignas(32) double a[4][4];
  for (int f = 0; f < 4; ++f) {
    for (int r = 0; r < kRegs; ++r) Store(a[f] + r * kLanes, acc[f][r]);
    out[f] = (a[f][0] + a[f][1]) + (a[f][2] + a[f][3]);
  }
#endif
  if (kPeak) {
    alignas(32) double top[4];
    for (int r = 0; r < kRegs; ++r) Store(top + r * kLanes, peak[r]);
    double m = top_tail;
    for (int l = 0; l < 4 && l < n; ++l) m = top[l] > m ? top[l] : m;
    out[4] = m;
  }
}

// WeightedSums for NF fields (unrolled).
template <int NF>
void Sums(const double* count, const double* const* v, int n, double* out) {
  // Four partial sums per field: one register with AVX, two with SSE2.
  constexpr int kRegs = 4 / kLanes;
  Vd acc[NF][kRegs];
  for (int f = 0; f < NF; ++f) {
    for (int r = 0; r < kRegs; ++r) acc[f][r] = Splat(0);
  }
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    for (int r = 0; r < kRegs; ++r) {
      const Vd c = Load(count + j + r * kLanes);
      for (int f = 0; f < NF; ++f) acc[f][r] += c * Load(v[f] + j + r * kLanes);
    }
  }
  for (int f = 0; f < NF; ++f) {
    alignas(32) double a[4];
    for (int r = 0; r < kRegs; ++r) Store(a + r * kLanes, acc[f][r]);
    for (int l = 0; j + l < n; ++l) a[l] += count[j + l] * v[f][j + l];
    out[f] = (a[0] + a[1]) + (a[2] + a[3]);
  }
}

}  // namespace

void WeightedSums(const double* count, const double* const* v, int nf, int n, double* out) {
  if (nf == 3) return Sums<3>(count, v, n, out);
  for (int f = 0; f < nf; ++f) Sums<1>(count, v + f, n, out + f);
}

void SumTelemetry(const BatchParams& p, const double* count, const double* const* v, int n,
                  double stretch, bool peak, double* out) {
  if (peak) return ObservePass<true>(p, count, v, n, stretch, out);
  ObservePass<false>(p, count, v, n, stretch, out);
}

#endif  // RECRUIT_SMA_LANES8

// The merge order has no sums: every clone has it (the 8-lane one counts eight ranks at once).
bool MergeOrder(const double* on, const double* temp, int n, int* order, double* t, int* idx) {
  // Off cohorts' temperatures in t[0..n0), on cohorts' in t[s1..s1 + n1) (s1 = n + 8), each
  // followed by 8 of +inf (read, never used), with their indices in idx: kLanes cohorts at a
  // time, appended by lane mask; on values other than 0 and 1, and NaN temperatures, give up.
  // Scratch: 2 (n + 8) each.
  constexpr int kPad = 8;  // >= kLanes (an append's width) and the count's unrolling
  const int s1 = n + kPad;
  int n0 = 0, n1 = 0, bad = 0;
  for (int j = 0; j < n; j += kLanes) {
    const int rest = n - j, valid = rest >= kLanes ? kAll : (1 << rest) - 1;
    const Vd o = rest >= kLanes ? Load(on + j) : LoadN(on + j, rest);
    const Vd x = rest >= kLanes ? Load(temp + j) : LoadN(temp + j, rest);
    const Mask is_off = Eq(o, 0.0), is_on = Eq(o, 1.0);
    bad |= ~Bits(And(Or(is_off, is_on), Eq(x, x))) & valid;
    const int off = Bits(is_off) & valid, on1 = Bits(is_on) & valid;
    AppendValues(t, n0, x, off);
    n0 = AppendLanes(idx, n0, j, off);
    AppendValues(t + s1, n1, x, on1);
    n1 = AppendLanes(idx + s1, n1, j, on1);
  }
  if (bad != 0) return false;
  for (int l = 0; l < kPad; ++l) t[n0 + l] = t[s1 + n1 + l] = HUGE_VAL;
  for (int j = 0; j < n; ++j) order[j] = -1;
  // Position = the group's start + how many of its temperatures are lower, counted for kLanes
  // cohorts at once (the lanes past the group are not used), four temperatures per iteration
  // (the +inf after the group counts for none): each comparison's all-ones lanes (integer -1)
  // subtracted from integer counts.
  using Counts = long long __attribute__((vector_size(sizeof(Vd))));
  auto less = [](double a, Vd x) { return reinterpret_cast<Counts>(ToVd(Lt(Splat(a), x))); };
  for (int g = 0; g < 2; ++g) {
    const double* tg = t + g * s1;
    const int* ig = idx + g * s1;
    const int ng = g == 0 ? n0 : n1, start = g == 0 ? 0 : n0;
    for (int b = 0; b < ng; b += kLanes) {
      const Vd x = Load(tg + b);
      Counts c0 = {}, c1 = {};
      for (int j = 0; j < ng; j += 4) {
        c0 -= less(tg[j], x);
        c1 -= less(tg[j + 1], x);
        c0 -= less(tg[j + 2], x);
        c1 -= less(tg[j + 3], x);
      }
      const Counts c = c0 + c1;
      for (int l = 0; l < kLanes && b + l < ng; ++l) {
        order[start + static_cast<int>(c[l])] = ig[b + l];
      }
    }
  }
  // Each group's ng positions lie in its ng slots: all filled unless two cohorts tie.
  for (int j = 0; j < n; ++j) bad |= order[j] < 0;
  return bad == 0;
}

#ifndef RECRUIT_SMA_LANES8
void Relabel(double* idx, int n, const int* remap) {
  int i = 0;
#if defined(__AVX2__)
  for (; i + 4 <= n; i += 4) {
    const __m128i from = _mm256_cvttpd_epi32(_mm256_loadu_pd(idx + i));
    _mm256_storeu_pd(idx + i, _mm256_cvtepi32_pd(_mm_i32gather_epi32(remap, from, 4)));
  }
#endif
  for (; i < n; ++i) idx[i] = remap[static_cast<int>(idx[i])];
}
#endif  // RECRUIT_SMA_LANES8

#pragma GCC diagnostic pop

}  // namespace recruit::sma::RECRUIT_SMA_BATCH_NS
