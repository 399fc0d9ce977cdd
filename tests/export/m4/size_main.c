/* size_main.c: the smallest program that keeps the exported controller whole (no stdio), for
 * its flash and RAM on the Cortex-M4F (arm-none-eabi-size; tests/export/export_test.cc). */
#include "recruit_controller.h"

static recruit_controller ctl;
static recruit_input in;
static recruit_output out;

int main(int argc, char **argv) {
  int k;
  (void)argv;
  recruit_init(&ctl);
  for (k = 0; k < argc; ++k) recruit_step(&ctl, &in, &out);
  return out.p_on[0] > 0;
}
