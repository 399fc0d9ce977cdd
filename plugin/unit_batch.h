// The batched cohort update's kernels (unit_batch.cc), compiled once for the build's instruction
// set (namespace batch_base) and, on x86-64 with GCC or Clang, once more for AVX2 (batch_avx2,
// RECRUIT_SMA_AVX2_CLONE): UnitModel::AdvanceCohorts picks the AVX2 one at run time when the CPU
// has it, so the portable build runs four lanes on machines that can. Both are bit-identical to
// the scalar update. Internal to plugin/; use UnitModel::AdvanceCohorts and SumTension.
#pragma once

namespace recruit::sma {

// The unit model's constants the kernels need (UnitModel private members, copied out).
struct BatchParams {
  double k_A, k_M, k_s, stretch_L;  // unit stiffness (N/m): austenite, martensite, series
  double latent, pn_h, pn_c;        // K per unit xi; K of T_eff per N (heating, cooling)
  double As, Af, Ms, Mf;            // transformation temperatures, C
  double heat_rate, cool_rate;      // pi / (Af - As), pi / (Ms - Mf)
  double ambient, rise_A, rise_dM;  // C; Joule rise (K) in austenite, martensite minus it
};

// Structure-of-arrays cohorts (UnitModel::Cohorts).
struct BatchCohorts {
  const double* on;
  double *temperature, *xi, *t_eff, *heat_scale, *cool_scale;
};

// The telemetry an update can give on its way (AdvanceCohorts with `obs`, UnitModel's): over the
// updated cohorts, out[0..4] as SumTelemetry of count and (on, temperature, xi) with `peak` at
// extension `stretch`, bit for bit, and out[5] the largest temperature. `done` is false when the
// kernel left them to the caller (UnitModel::AdvanceCohorts then sums afresh).
struct BatchObserve {
  const double* count;
  double stretch;
  double out[6];
  bool done;
};

// Kernels: AdvanceCohorts and SumTension as UnitModel's; AdvanceBlockBeforeUpdatedTail is
// AdvanceCohorts for kLanes < n <= 2 kLanes cohorts of which the caller has already updated those
// past the first kLanes (the telemetry, with obs, of all n); WeightedSums sets out[f] to the sum
// over j < n of count[j] * v[f][j] for f < nf <= 3, in four partial sums (lane j mod 4) added as
// (s0 + s1) + (s2 + s3): the same in both clones, exact for one cohort. SumTelemetry is
// WeightedSums of v[0..2] and SumTension of xi = v[2] in one pass, bit for bit, out[0..3]; with
// `peak` also out[4] = the largest Tension(xi[j], stretch), 0 for none.
namespace batch_base {
void AdvanceCohorts(const BatchParams& p, const BatchCohorts& c, int n, double stretch,
                    double decay, BatchObserve* obs = nullptr);
void AdvanceBlockBeforeUpdatedTail(const BatchParams& p, const BatchCohorts& c, int n,
                                   double stretch, double decay, BatchObserve* obs);
double SumTension(const BatchParams& p, const double* count, const double* xi, int n,
                  double stretch);
void WeightedSums(const double* count, const double* const* v, int nf, int n, double* out);
void SumTelemetry(const BatchParams& p, const double* count, const double* const* v, int n,
                  double stretch, bool peak, double* out);
// idx[i] = remap[idx[i]] for i < n (indices held as doubles).
void Relabel(double* idx, int n, const int* remap);
// UnitModel::MergeOrder; t and idx: 2 (n + 8) of scratch each.
bool MergeOrder(const double* on, const double* temp, int n, int* order, double* t, int* idx);
}  // namespace batch_base

#ifdef RECRUIT_SMA_AVX2_CLONE
namespace batch_avx2 {
void AdvanceCohorts(const BatchParams& p, const BatchCohorts& c, int n, double stretch,
                    double decay, BatchObserve* obs = nullptr);
void AdvanceBlockBeforeUpdatedTail(const BatchParams& p, const BatchCohorts& c, int n,
                                   double stretch, double decay, BatchObserve* obs);
double SumTension(const BatchParams& p, const double* count, const double* xi, int n,
                  double stretch);
void WeightedSums(const double* count, const double* const* v, int nf, int n, double* out);
void SumTelemetry(const BatchParams& p, const double* count, const double* const* v, int n,
                  double stretch, bool peak, double* out);
void Relabel(double* idx, int n, const int* remap);
bool MergeOrder(const double* on, const double* temp, int n, int* order, double* t, int* idx);
}  // namespace batch_avx2
#endif

#ifdef RECRUIT_SMA_AVX512_CLONE
// AVX-512 (F and DQ), 8 lanes: the update and the merge order; the sums keep their four partial
// sums (AVX2).
namespace batch_avx512 {
void AdvanceCohorts(const BatchParams& p, const BatchCohorts& c, int n, double stretch,
                    double decay, BatchObserve* obs = nullptr);
bool MergeOrder(const double* on, const double* temp, int n, int* order, double* t, int* idx);
}  // namespace batch_avx512
#endif

}  // namespace recruit::sma
