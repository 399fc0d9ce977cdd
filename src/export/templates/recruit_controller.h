/* recruit_controller.h: the broadcast recruitment controller of task "@TASK@", exported by
 * `recruit export` (docs/export.md) from recruit @VERSION@. Generated: do not edit.
 *   @SETTINGS@
 * C99, no heap, no global state: all state lives in the structs below, which the caller owns.
 * Depends on the C library's math only (@MATH@). */
#ifndef RECRUIT_CONTROLLER_H
#define RECRUIT_CONTROLLER_H

#ifdef __cplusplus
extern "C" {
#endif

/* @NAME@ are the generator's placeholders, kept as they are: */
/* clang-format off */
typedef @REAL@ recruit_real;

#define RECRUIT_NUM_BUNDLES @NB@
#define RECRUIT_MAX_STATES @MMAX@ /* largest number of model states over the bundles */
#define RECRUIT_MAX_ENTRIES @NNZMAX@ /* largest number of nonzeros of a bundle's A */
#define RECRUIT_PACKED (RECRUIT_MAX_STATES * (RECRUIT_MAX_STATES + 1) / 2)
#define RECRUIT_TRACKS_ANGLE @ANGLE@ /* 1: reference and outer loop in rad; 0: force (N) */
@LOOP_DEFINES@

/* A bundle's constants (the identified model, unit geometry, gains): in recruit_controller.c. */
typedef struct recruit_bundle_params recruit_bundle_params;

/* One bundle's state: the population Kalman filter's estimate (units per model state) and its
 * covariance (upper triangle packed by columns), or the output estimator's count. */
typedef struct {
  const recruit_bundle_params *params;
  recruit_real x[RECRUIT_MAX_STATES];
  recruit_real P[RECRUIT_PACKED];
  recruit_real count; /* output estimator */
  int sparse_steps;   /* predictions since P was last projected onto 1^T P = 0 */
} recruit_bundle;

/* Scratch of one step, shared by the bundles of a controller; holds nothing between calls. */
typedef struct {
  recruit_real M[RECRUIT_PACKED]; /* P - diag(xq) before the prediction */
  recruit_real val[RECRUIT_MAX_ENTRIES];
  recruit_real h[RECRUIT_MAX_STATES], u[RECRUIT_MAX_STATES], v[RECRUIT_MAX_STATES];
  recruit_real xq[RECRUIT_MAX_STATES], t[RECRUIT_MAX_STATES], s[RECRUIT_MAX_STATES];
} recruit_work;

/* clang-format off */
/* The task's controller: every bundle, the outer loop's integral (angle tasks). */
typedef struct {
  recruit_bundle bundle[RECRUIT_NUM_BUNDLES];
  recruit_work work;
@LOOP_STATE@
} recruit_controller;

/* What the controller reads at a control instant (every dT = @DT@ s). */
typedef struct {
@LOOP_INPUT@
  recruit_real force[RECRUIT_NUM_BUNDLES];  /* N, each bundle's load cell; NaN = lost sample */
  recruit_real length[RECRUIT_NUM_BUNDLES]; /* m, each bundle's length coordinate; NaN = none */
} recruit_input;
/* clang-format on */

/* What it decides: broadcast p_on / p_off to bundle i's units. */
typedef struct {
  recruit_real force_reference[RECRUIT_NUM_BUNDLES]; /* N */
  recruit_real p_on[RECRUIT_NUM_BUNDLES], p_off[RECRUIT_NUM_BUNDLES];
  recruit_real estimated_on[RECRUIT_NUM_BUNDLES]; /* units whose heater is on */
  recruit_real variance[RECRUIT_NUM_BUNDLES];     /* units^2; NaN for the output estimator */
} recruit_output;

/* Sets every bundle to its initial belief (all units off) and the outer loop to rest. */
void recruit_init(recruit_controller *c);
/* One control instant: outer loop, then each bundle's estimate and broadcast. */
void recruit_step(recruit_controller *c, const recruit_input *in, recruit_output *out);

/* One bundle alone (index 0 .. RECRUIT_NUM_BUNDLES - 1), for another outer loop: init, then
 * per instant the force reference (N), its load cell (N) and length (m) in, the broadcast and
 * the estimate out. `work` is scratch (any recruit_work, e.g. a controller's). */
void recruit_bundle_init(recruit_bundle *b, int index);
void recruit_bundle_step(recruit_bundle *b, recruit_work *work, recruit_real force_reference,
                         recruit_real force, recruit_real length, recruit_real *p_on,
                         recruit_real *p_off, recruit_real *estimated_on, recruit_real *variance);

#ifdef __cplusplus
}
#endif
#endif /* RECRUIT_CONTROLLER_H */
