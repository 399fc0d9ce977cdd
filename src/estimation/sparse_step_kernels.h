// The sparse filter step's kernels: column combinations (pass 1 of the prediction, u = P h),
// the upper triangle of A B (pass 2), the rank-1 update P - w w^T, transposition and mirror.
// Not a header of its own: included twice by population_kalman_filter.h (hence no include
// guard; named .h so that it is installed with the headers): into kf_detail::base for the
// build's instruction set (Eigen's packets; FMA in the x86-64-v3 build) and, in the portable
// x86-64 build, into kf_detail::avx, where every function is compiled for AVX by a target
// attribute (not by a compiler flag, so that no inline code shared with other files is
// compiled for AVX) and runs only where the CPU has AVX (PopulationKalmanFilterT::avx_kernels).
//
// The two copies give bit-identical results: AVX without FMA rounds a multiply and an add
// separately, as SSE2 does, and each output element goes through the same operations in the
// same order in both (a0 s0, plus the old value when accumulating, then + a1 s1, then + a2 s2).
// Which elements take the scalar tail is the same too: the AVX copy runs 4 lanes, then one
// 2-lane step, then the scalar tail of the SSE2 copy (len mod 2 elements).
//
// Expects, defined by the includer: RECRUIT_KF_AVX (0 or 1), RECRUIT_KF_INLINE (inlined kernel
// pieces) and RECRUIT_KF_PASS (the entry points: always inlined in the base copy; not inlined
// in the AVX copy, whose callers are compiled for the baseline).
#ifndef RECRUIT_KF_AVX
#error "sparse_step_kernels.h is included by population_kalman_filter.h only"
#endif

#if RECRUIT_KF_AVX
// 4 and 2 lanes; MulAdd is a multiply then an add (two roundings), as Eigen's SSE2 pmadd.
struct Lanes {
  using V = __m256d;
  static constexpr int kSize = 4;
  RECRUIT_KF_INLINE static V Set1(double a) { return _mm256_set1_pd(a); }
  RECRUIT_KF_INLINE static V Load(const double* p) { return _mm256_loadu_pd(p); }
  RECRUIT_KF_INLINE static void Store(double* p, V v) { _mm256_storeu_pd(p, v); }
  RECRUIT_KF_INLINE static V Mul(V a, V b) { return _mm256_mul_pd(a, b); }
  RECRUIT_KF_INLINE static V MulAdd(V a, V b, V c) { return _mm256_add_pd(_mm256_mul_pd(a, b), c); }
};
struct HalfLanes {
  using V = __m128d;
  static constexpr int kSize = 2;
  RECRUIT_KF_INLINE static V Load(const double* p) { return _mm_loadu_pd(p); }
  RECRUIT_KF_INLINE static void Store(double* p, V v) { _mm_storeu_pd(p, v); }
  RECRUIT_KF_INLINE static V Mul(V a, V b) { return _mm_mul_pd(a, b); }
  RECRUIT_KF_INLINE static V MulAdd(V a, V b, V c) { return _mm_add_pd(_mm_mul_pd(a, b), c); }
};
constexpr int kSmallestStep = 2;
#else
// Eigen's packet of the build (2 lanes with SSE2; 4 with a fused multiply-add in x86-64-v3).
struct Lanes {
  using V = Packet;
  static constexpr int kSize = kPacket;
  RECRUIT_KF_INLINE static V Set1(double a) { return Eigen::internal::pset1<Packet>(a); }
  RECRUIT_KF_INLINE static V Load(const double* p) { return Eigen::internal::ploadu<Packet>(p); }
  RECRUIT_KF_INLINE static void Store(double* p, const V& v) { Eigen::internal::pstoreu(p, v); }
  RECRUIT_KF_INLINE static V Mul(const V& a, const V& b) { return Eigen::internal::pmul(a, b); }
  RECRUIT_KF_INLINE static V MulAdd(const V& a, const V& b, const V& c) {
    return Eigen::internal::pmadd(a, b, c);
  }
};
constexpr int kSmallestStep = kPacket;
#endif

// One packet of CombineColumns.
template <class L, int T, bool Acc>
RECRUIT_KF_INLINE void CombineStep(double* __restrict out, const double* __restrict s0,
                                   const double* __restrict s1, const double* __restrict s2,
                                   typename L::V p0, typename L::V p1, typename L::V p2) {
  typename L::V v = Acc ? L::MulAdd(p0, L::Load(s0), L::Load(out)) : L::Mul(p0, L::Load(s0));
  if (T > 1) v = L::MulAdd(p1, L::Load(s1), v);
  if (T > 2) v = L::MulAdd(p2, L::Load(s2), v);
  L::Store(out, v);
}

// out[0..len) = (Acc ? out : 0) + a0 s0 + a1 s1 + a2 s2 (the first T of the three terms).
template <int Len, int T, bool Acc>
RECRUIT_KF_INLINE void CombineColumns(double* __restrict out, const double* __restrict s0,
                                      const double* __restrict s1, const double* __restrict s2,
                                      double a0, double a1, double a2, Eigen::Index len_dynamic) {
  const Eigen::Index len = Len == Eigen::Dynamic ? len_dynamic : Len;
  const typename Lanes::V p0 = Lanes::Set1(a0), p1 = Lanes::Set1(a1), p2 = Lanes::Set1(a2);
  Eigen::Index r = 0;
  if constexpr (Len == Eigen::Dynamic || Len / Lanes::kSize <= 16) {
    // Fixed lengths are unrolled completely by the compiler.
    for (; r + Lanes::kSize <= len; r += Lanes::kSize) {
      CombineStep<Lanes, T, Acc>(out + r, s0 + r, s1 + r, s2 + r, p0, p1, p2);
    }
  } else {
    // Long fixed lengths (m = 50 with SSE2): partly (measured: 6k fewer instructions a step).
#pragma GCC unroll 8
    for (; r + Lanes::kSize <= len; r += Lanes::kSize) {
      CombineStep<Lanes, T, Acc>(out + r, s0 + r, s1 + r, s2 + r, p0, p1, p2);
    }
  }
#if RECRUIT_KF_AVX
  if (r + 2 <= len) {  // the SSE2 copy's last packet
    CombineStep<HalfLanes, T, Acc>(out + r, s0 + r, s1 + r, s2 + r, _mm256_castpd256_pd128(p0),
                                   _mm256_castpd256_pd128(p1), _mm256_castpd256_pd128(p2));
    r += 2;
  }
#endif
  if constexpr (Len != Eigen::Dynamic && Len % kSmallestStep == 0) return;  // no tail
  for (; r < len; ++r) {
    double v = (Acc ? out[r] : 0.0) + a0 * s0[r];
    if (T > 1) v += a1 * s1[r];
    if (T > 2) v += a2 * s2[r];
    out[r] = v;
  }
}

// out[0..len) = sum_k a[k] src(0..len, c[k]) for n terms (column-major src, leading dimension
// ld); zero for n = 0. Up to three columns per loop, so that `out` is written once per three
// terms. Len: the length when fixed at compile time (unrolled), else Eigen::Dynamic.
template <int Len>
RECRUIT_KF_INLINE void RowCombination(double* __restrict out, const double* __restrict src,
                                      Eigen::Index ld, Eigen::Index len_dynamic, const int* c,
                                      const double* a, int n) {
  const Eigen::Index len = Len == Eigen::Dynamic ? len_dynamic : Len;
  if (n == 0) {
    for (Eigen::Index r = 0; r < len; ++r) out[r] = 0.0;
    return;
  }
  const double* s0 = src + c[0] * ld;
  // The first one to three terms initialise out, the rest accumulate three at a time.
  if (n == 1) {
    CombineColumns<Len, 1, false>(out, s0, s0, s0, a[0], 0.0, 0.0, len);
    return;
  }
  if (n == 2) {
    CombineColumns<Len, 2, false>(out, s0, src + c[1] * ld, s0, a[0], a[1], 0.0, len);
    return;
  }
  CombineColumns<Len, 3, false>(out, s0, src + c[1] * ld, src + c[2] * ld, a[0], a[1], a[2], len);
  int k = 3;
  for (; k + 3 <= n; k += 3) {
    CombineColumns<Len, 3, true>(out, src + c[k] * ld, src + c[k + 1] * ld, src + c[k + 2] * ld,
                                 a[k], a[k + 1], a[k + 2], len);
  }
  if (n - k == 2) {
    CombineColumns<Len, 2, true>(out, src + c[k] * ld, src + c[k + 1] * ld, s0, a[k], a[k + 1], 0.0,
                                 len);
  } else if (n - k == 1) {
    CombineColumns<Len, 1, true>(out, src + c[k] * ld, s0, s0, a[k], 0.0, 0.0, len);
  }
}

// The 2 x 2 block at src (leading dimension m) transposed into the block at dst.
RECRUIT_KF_INLINE void TransposeBlock2(const double* src, double* dst, Eigen::Index m) {
#ifdef __SSE2__
  const __m128d c0 = _mm_loadu_pd(src);
  const __m128d c1 = _mm_loadu_pd(src + m);
  _mm_storeu_pd(dst, _mm_unpacklo_pd(c0, c1));
  _mm_storeu_pd(dst + m, _mm_unpackhi_pd(c0, c1));
#else
  const double a = src[0], b = src[1], c = src[m], d = src[m + 1];
  dst[0] = a, dst[1] = c, dst[m] = b, dst[m + 1] = d;
#endif
}

#if RECRUIT_KF_AVX
// The 4 x 4 block at src (leading dimension m) transposed into the block at dst.
RECRUIT_KF_INLINE void TransposeBlock4(const double* src, double* dst, Eigen::Index m) {
  const __m256d c0 = _mm256_loadu_pd(src), c1 = _mm256_loadu_pd(src + m);
  const __m256d c2 = _mm256_loadu_pd(src + 2 * m), c3 = _mm256_loadu_pd(src + 3 * m);
  const __m256d lo01 = _mm256_unpacklo_pd(c0, c1), hi01 = _mm256_unpackhi_pd(c0, c1);
  const __m256d lo23 = _mm256_unpacklo_pd(c2, c3), hi23 = _mm256_unpackhi_pd(c2, c3);
  _mm256_storeu_pd(dst, _mm256_permute2f128_pd(lo01, lo23, 0x20));
  _mm256_storeu_pd(dst + m, _mm256_permute2f128_pd(hi01, hi23, 0x20));
  _mm256_storeu_pd(dst + 2 * m, _mm256_permute2f128_pd(lo01, lo23, 0x31));
  _mm256_storeu_pd(dst + 3 * m, _mm256_permute2f128_pd(hi01, hi23, 0x31));
}
#endif

// Block size of Transpose and MirrorUpper (then 2 x 2 blocks for the rest of an even m).
#if RECRUIT_KF_AVX
constexpr Eigen::Index kBlock = 4;
RECRUIT_KF_INLINE void TransposeBlock(const double* src, double* dst, Eigen::Index m) {
  TransposeBlock4(src, dst, m);
}
#else
constexpr Eigen::Index kBlock = 2;
RECRUIT_KF_INLINE void TransposeBlock(const double* src, double* dst, Eigen::Index m) {
  TransposeBlock2(src, dst, m);
}
#endif

// The kernel entry points of one instruction set (PopulationKalmanFilterT picks a copy).
struct Kernels {
  // The values of a broadcast A(p_on, p_off) in its compressed rows (PredictBroadcast), element
  // by element: p = on p_off + off p_on (exact: one of on, off is 0), val = (1 - p) base +
  // target p (target is 1 or 0).
  RECRUIT_KF_PASS static void FillBroadcast(size_t n, double p_on, double p_off,
                                            const double* __restrict on,
                                            const double* __restrict off,
                                            const double* __restrict base,
                                            const double* __restrict target,
                                            double* __restrict val) {
    for (size_t e = 0; e < n; ++e) {
      const double p = on[e] * p_off + off[e] * p_on;
      val[e] = (1.0 - p) * base[e] + target[e] * p;
    }
  }

  // Pass 1 of the sparse prediction: column i of B is row i of A applied to P's columns,
  // B(:, i) = sum_l A(i, l) P(:, l) (A in compressed rows: ptr, col, val).
  template <int Len>
  RECRUIT_KF_PASS static void CombineRows(double* B, const double* P, Eigen::Index m,
                                          const int* ptr, const int* col, const double* val) {
    for (Eigen::Index i = 0; i < m; ++i) {
      RowCombination<Len>(B + i * m, P, m, m, col + ptr[i], val + ptr[i], ptr[i + 1] - ptr[i]);
    }
  }

  // Pass 2: the upper triangle of A B into P (Bt = B^T, so that its rows are contiguous), plus
  // diag(ax) and the upper triangle of gqg when given (nullptr: none). Column j is computed on
  // rows 0..j rounded up to a multiple of kRound (the same length for each group of kRound
  // columns); the rows below the diagonal are left to the mirror. The rounding changes no
  // element of the upper triangle (each is computed the same way whatever the length). For a
  // fixed m of at most 16 groups the groups are unrolled at compile time, each with its length
  // fixed. (Groups of 4 with SSE2 unroll m = 50 too, 4 % fewer instructions, but measured 10 %
  // slower: the code is much larger.)
  template <int Len>
  RECRUIT_KF_PASS static void UpperProduct(double* P, const double* Bt, Eigen::Index m,
                                           const int* ptr, const int* col, const double* val,
                                           const double* ax, const double* gqg) {
    if constexpr (Len != Eigen::Dynamic && Len <= 16 * kRound) {
      UpperGroups<Len>(P, Bt, ptr, col, val, ax, gqg,
                       std::make_integer_sequence<int, (Len + kRound - 1) / kRound>());
    } else {
      for (Eigen::Index j = 0; j < m; ++j) {
        const Eigen::Index len = std::min<Eigen::Index>(m, (j + kRound) & ~(kRound - 1));
        UpperColumns<Eigen::Dynamic>(P, Bt, m, j, j + 1, len, ptr, col, val, ax, gqg);
      }
    }
  }

  static constexpr Eigen::Index kRound = Lanes::kSize > 1 ? Lanes::kSize : 2;  // whole packets

  // Columns j0..j1 of pass 2, each on rows 0..len (len fixed at compile time unless Len is
  // Eigen::Dynamic).
  template <int Len>
  RECRUIT_KF_INLINE static void UpperColumns(double* P, const double* Bt, Eigen::Index m,
                                             Eigen::Index j0, Eigen::Index j1, Eigen::Index len,
                                             const int* ptr, const int* col, const double* val,
                                             const double* ax, const double* gqg) {
    for (Eigen::Index j = j0; j < j1; ++j) {
      double* pj = P + j * m;
      RowCombination<Len>(pj, Bt, m, len, col + ptr[j], val + ptr[j], ptr[j + 1] - ptr[j]);
      if (ax != nullptr) pj[j] += ax[j];
      if (gqg != nullptr) {
        for (Eigen::Index i = 0; i <= j; ++i) pj[i] += gqg[i + j * m];
      }
    }
  }

  // The groups G... of kRound columns of pass 2 for the fixed size M, one after another, each
  // on rows 0..min(M, (G + 1) kRound). A fold over the group indices, not a recursion (group G
  // calling group G + 1): inlined recursively, every group's function held all the groups after
  // it, and the compile time was quadratic in the number of groups (the AVX copy for m = 50:
  // 91 groups' code for 13). The same operations in the same order: the same results.
  template <int M, int... G>
  RECRUIT_KF_INLINE static void UpperGroups(double* P, const double* Bt, const int* ptr,
                                            const int* col, const double* val, const double* ax,
                                            const double* gqg, std::integer_sequence<int, G...>) {
    (UpperColumns<std::min<int>(M, (G + 1) * kRound)>(
         P, Bt, M, G * kRound, std::min<int>(M, (G + 1) * kRound),
         std::min<int>(M, (G + 1) * kRound), ptr, col, val, ax, gqg),
     ...);
  }

  // out = P h for the m x m column-major P: the combination of all of P's columns (iota = 0,
  // 1, ..., m - 1).
  template <int Len>
  RECRUIT_KF_PASS static void MatVec(double* out, const double* P, Eigen::Index m, const int* iota,
                                     const double* h) {
    RowCombination<Len>(out, P, m, m, iota, h, static_cast<int>(m));
  }

  // P -= w w^T (the same arithmetic for (i, j) and (j, i): P stays exactly symmetric).
  template <int Len>
  RECRUIT_KF_PASS static void SubtractOuter(double* P, const double* w, Eigen::Index m) {
    for (Eigen::Index j = 0; j < m; ++j) {
      CombineColumns<Len, 1, true>(P + j * m, w, w, w, -w[j], 0.0, 0.0, m);
    }
  }

  // dst = src^T, m x m column-major; blocks of kBlock, then 2 x 2, when m is even.
  RECRUIT_KF_PASS static void Transpose(const double* __restrict src, double* __restrict dst,
                                        Eigen::Index m) {
    if (m % 2 != 0) {
      for (Eigen::Index j = 0; j < m; ++j) {
        for (Eigen::Index i = 0; i < m; ++i) dst[j + i * m] = src[i + j * m];
      }
      return;
    }
    const Eigen::Index mb = m - m % kBlock;  // [0, mb)^2 in blocks of kBlock
    for (Eigen::Index j = 0; j < mb; j += kBlock) {
      for (Eigen::Index i = 0; i < mb; i += kBlock)
        TransposeBlock(src + i + j * m, dst + j + i * m, m);
    }
    for (Eigen::Index j = 0; j < m; j += 2) {  // rows mb.. of every column
      for (Eigen::Index i = mb; i < m; i += 2) TransposeBlock2(src + i + j * m, dst + j + i * m, m);
    }
    for (Eigen::Index j = mb; j < m; j += 2) {  // columns mb.., rows 0..mb
      for (Eigen::Index i = 0; i < mb; i += 2) TransposeBlock2(src + i + j * m, dst + j + i * m, m);
    }
  }

  // Copies the strict upper triangle of the m x m column-major P to its lower triangle.
  RECRUIT_KF_PASS static void MirrorUpper(double* P, Eigen::Index m) {
    if (m % 2 != 0) {
      for (Eigen::Index i = 0; i < m; ++i) {
        for (Eigen::Index j = i + 1; j < m; ++j) P[j + i * m] = P[i + j * m];
      }
      return;
    }
    const Eigen::Index mb = m - m % kBlock;
    for (Eigen::Index j = 0; j < mb; j += kBlock) {
      for (Eigen::Index i = 0; i < j; i += kBlock) TransposeBlock(P + i + j * m, P + j + i * m, m);
      // Inside the diagonal block: its 2 x 2 diagonal blocks, and (kBlock = 4) the one above.
      if (kBlock == 4) TransposeBlock2(P + j + (j + 2) * m, P + j + 2 + j * m, m);
      for (Eigen::Index d = j; d < j + kBlock; d += 2) P[d + 1 + d * m] = P[d + (d + 1) * m];
    }
    for (Eigen::Index j = mb; j < m; j += 2) {  // columns mb.. in 2 x 2 blocks
      for (Eigen::Index i = 0; i < j; i += 2) TransposeBlock2(P + i + j * m, P + j + i * m, m);
      P[j + 1 + j * m] = P[j + (j + 1) * m];
    }
  }
};
