/* firmware.c: how firmware wires the two exported packages together (docs/export.md): at each
 * control instant, sample, step the controller, and broadcast one frame per bundle. Compiled for
 * the Cortex-M4F by tests/export/export_test.cc (the sensor and radio calls are stubs). */
#include <stdint.h>

#include "recruit_controller.h"
#include "recruit_unit.h"

/* Board-specific: stubs here. */
static float load_cell(int bundle) { return (float)bundle; }
static float tendon_length(int bundle) { return 0.2f + 0.01f * (float)bundle; }
static float reference_now(void) { return 0.5f; }
static float encoder_angle(void) { return 0.4f; }
static float encoder_velocity(void) { return 0.0f; }
static volatile uint8_t radio[RECRUIT_WIRE_SIZE];
static void radio_send(const uint8_t *frame) {
  int i;
  for (i = 0; i < RECRUIT_WIRE_SIZE; ++i) radio[i] = frame[i];
}

static recruit_controller ctl;

/* Called every dT by a timer. */
void control_instant(uint16_t k) {
  recruit_input in;
  recruit_output out;
  int i;
  in.reference = reference_now();
  in.angle = encoder_angle();
  in.angular_velocity = encoder_velocity();
  for (i = 0; i < RECRUIT_NUM_BUNDLES; ++i) {
    in.force[i] = load_cell(i);
    in.length[i] = tendon_length(i);
  }
  recruit_step(&ctl, &in, &out);
  for (i = 0; i < RECRUIT_NUM_BUNDLES; ++i) {
    recruit_wire_message m;
    uint8_t frame[RECRUIT_WIRE_SIZE];
    m.bundle = (uint8_t)i;
    m.sequence = k;
    m.p_on = recruit_wire_quantize(out.p_on[i]);
    m.p_off = recruit_wire_quantize(out.p_off[i]);
    recruit_wire_encode(&m, frame);
    radio_send(frame);
  }
}

int main(void) {
  uint16_t k;
  recruit_init(&ctl);
  for (k = 0; k < 3; ++k) control_instant(k);
  return radio[0] == RECRUIT_WIRE_SYNC ? 0 : 1;
}
