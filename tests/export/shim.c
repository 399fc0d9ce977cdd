/* shim.c: the exported controller behind a type-independent interface, so that a test compiled
 * once (tests/export/export_test.cc) loads packages of either precision and any number of
 * bundles and joints (dlopen). Inputs and outputs are doubles; the package's own type is used
 * inside. */
#include <stddef.h>

#include "recruit_controller.h"

#ifndef RECRUIT_AUTO_LOOP
#define RECRUIT_NUM_JOINTS 1
#endif

size_t shim_size(void) { return sizeof(recruit_controller); }
int shim_bundles(void) { return RECRUIT_NUM_BUNDLES; }
int shim_joints(void) { return RECRUIT_NUM_JOINTS; }
void shim_init(void *c) { recruit_init((recruit_controller *)c); }

/* The reference pose of the last step and whether the references matched it (self-tuned loops);
 * -1 without them. */
int shim_pose(const void *c, int *exact) {
#ifdef RECRUIT_AUTO_LOOP
  *exact = ((const recruit_controller *)c)->pose_exact;
  return ((const recruit_controller *)c)->pose;
#else
  (void)c;
  *exact = 0;
  return -1;
#endif
}

/* in: reference[nj], angle[nj], angular velocity[nj], force[nb], length[nb] (nj = 1 without
 * self-tuned loops). out: per bundle force reference, p_on, p_off, estimated on, variance. */
void shim_step(void *c, const double *in, double *out) {
  recruit_input x;
  recruit_output y;
  int i;
  const int nb = RECRUIT_NUM_BUNDLES, nj = RECRUIT_NUM_JOINTS;
#ifdef RECRUIT_AUTO_LOOP
  for (i = 0; i < nj; ++i) {
    x.reference[i] = (recruit_real)in[i];
    x.angle[i] = (recruit_real)in[nj + i];
    x.angular_velocity[i] = (recruit_real)in[2 * nj + i];
  }
#else
  x.reference = (recruit_real)in[0];
  x.angle = (recruit_real)in[1];
  x.angular_velocity = (recruit_real)in[2];
#endif
  for (i = 0; i < nb; ++i) {
    x.force[i] = (recruit_real)in[3 * nj + i];
    x.length[i] = (recruit_real)in[3 * nj + nb + i];
  }
  recruit_step((recruit_controller *)c, &x, &y);
  for (i = 0; i < nb; ++i) {
    out[5 * i + 0] = y.force_reference[i];
    out[5 * i + 1] = y.p_on[i];
    out[5 * i + 2] = y.p_off[i];
    out[5 * i + 3] = y.estimated_on[i];
    out[5 * i + 4] = y.variance[i];
  }
}
