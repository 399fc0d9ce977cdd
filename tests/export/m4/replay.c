/* replay.c: runs the exported float controller over a recorded log of control instants and
 * prints every output's bit pattern; the same source for the host and the Cortex-M4F under
 * QEMU (tests/export/export_test.cc compares the two).
 * Log: "instants bundles", then per instant the float bit patterns (hex) of reference, angle,
 * angular velocity (each per driven joint for the self-tuned loops: nj of each), force[nb],
 * length[nb] (newlib's strtof misrounds: bits, not decimals).
 * Output: per instant and bundle "k i force_reference p_on p_off estimated_on variance" (hex
 * bits), then "ticks T" (SysTick ticks spent in recruit_step with QEMU's -icount shift=0: one
 * tick per 40 instructions; 0 on the host). */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "recruit_controller.h"

#ifndef RECRUIT_AUTO_LOOP
#define RECRUIT_NUM_JOINTS 1
#endif
#define NV (3 * RECRUIT_NUM_JOINTS + 2 * RECRUIT_NUM_BUNDLES)

static recruit_controller ctl; /* static: its size is the package's RAM (.bss) */

/* Float bit patterns in and out (a double package's outputs are rounded to float). */
static uint32_t bits(recruit_real v) {
  const float f = (float)v;
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

static recruit_real real_of(unsigned long b) {
  const uint32_t u = (uint32_t)b;
  float f;
  memcpy(&f, &u, sizeof f);
  return (recruit_real)f;
}

#ifdef M4_SYSTICK
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
static void tick_start(void) {
  SYST_RVR = 0x00FFFFFFu;
  SYST_CVR = 0;
  SYST_CSR = 5u; /* processor clock, no interrupt, enabled */
}
static uint32_t tick_now(void) { return SYST_CVR; }
#else
static void tick_start(void) {}
static uint32_t tick_now(void) { return 0; }
#endif

int main(int argc, char **argv) {
  const char *path = argc > 1 ? argv[1] : "log.txt";
  int n, nb, k, i;
  unsigned long b;
  uint64_t ticks = 0;
  recruit_input in;
  recruit_output out;
  FILE *f = fopen(path, "r");
  if (!f) {
    printf("cannot open %s\n", path);
    return 3;
  }
  if (fscanf(f, "%d %d", &n, &nb) != 2 || nb != RECRUIT_NUM_BUNDLES) return 4;
  recruit_init(&ctl);
  tick_start();
  for (k = 0; k < n; ++k) {
    const int nj = RECRUIT_NUM_JOINTS;
    recruit_real v[NV];
    uint32_t t0, t1;
    for (i = 0; i < NV; ++i) {
      if (fscanf(f, "%lx", &b) != 1) return 5;
      v[i] = real_of(b);
    }
#ifdef RECRUIT_AUTO_LOOP
    for (i = 0; i < nj; ++i) {
      in.reference[i] = v[i];
      in.angle[i] = v[nj + i];
      in.angular_velocity[i] = v[2 * nj + i];
    }
#else
    in.reference = v[0];
    in.angle = v[1];
    in.angular_velocity = v[2];
#endif
    for (i = 0; i < nb; ++i) {
      in.force[i] = v[3 * nj + i];
      in.length[i] = v[3 * nj + nb + i];
    }
    t0 = tick_now();
    recruit_step(&ctl, &in, &out);
    t1 = tick_now();
    ticks += (t0 - t1) & 0x00FFFFFFu; /* SysTick counts down */
    for (i = 0; i < nb; ++i) {
      printf("%d %d %08lx %08lx %08lx %08lx %08lx\n", k, i,
             (unsigned long)bits(out.force_reference[i]), (unsigned long)bits(out.p_on[i]),
             (unsigned long)bits(out.p_off[i]), (unsigned long)bits(out.estimated_on[i]),
             (unsigned long)bits(out.variance[i]));
    }
  }
  fclose(f);
  printf("ticks %lu steps %d\n", (unsigned long)ticks, n);
  return 0;
}
