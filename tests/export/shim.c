/* shim.c: the exported controller behind a type-independent interface, so that a test compiled
 * once (tests/export/export_test.cc) loads packages of either precision and any number of
 * bundles (dlopen). Inputs and outputs are doubles; the package's own type is used inside. */
#include <stddef.h>

#include "recruit_controller.h"

size_t shim_size(void) { return sizeof(recruit_controller); }
int shim_bundles(void) { return RECRUIT_NUM_BUNDLES; }
void shim_init(void *c) { recruit_init((recruit_controller *)c); }

/* in: reference, angle, angular velocity, force[nb], length[nb].
 * out: per bundle force reference, p_on, p_off, estimated on, variance. */
void shim_step(void *c, const double *in, double *out) {
  recruit_input x;
  recruit_output y;
  int i;
  const int nb = RECRUIT_NUM_BUNDLES;
  x.reference = (recruit_real)in[0];
  x.angle = (recruit_real)in[1];
  x.angular_velocity = (recruit_real)in[2];
  for (i = 0; i < nb; ++i) {
    x.force[i] = (recruit_real)in[3 + i];
    x.length[i] = (recruit_real)in[3 + nb + i];
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
