/* recruit_unit.h: the unit side of broadcast recruitment control, exported by `recruit export`
 * (docs/export.md, docs/broadcast-wire-format.md). Generated: do not edit.
 * Each SMA unit runs this state machine on its own microcontroller: it receives the controller's
 * broadcast frame, checks it, and draws its own transition with its own seeded generator
 * (PCG32), so that the number of units switching is binomial with the broadcast probability.
 * C99, no heap, no global state; needs <stdint.h> only. */
#ifndef RECRUIT_UNIT_H
#define RECRUIT_UNIT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The broadcast frame: 9 bytes (docs/broadcast-wire-format.md). */
#define RECRUIT_WIRE_SIZE 9
#define RECRUIT_WIRE_SYNC 0xA5u
#define RECRUIT_WIRE_ONE 32768u /* a probability of 1 on the wire */

typedef struct {
  uint8_t bundle;    /* which bundle's units act on it */
  uint16_t sequence; /* control instant, modulo 65536 */
  uint16_t p_on;     /* Pr(an off unit turns on) x 32768, 0 .. 32768 */
  uint16_t p_off;    /* Pr(an on unit turns off) x 32768, 0 .. 32768 */
} recruit_wire_message;

/* A probability in [0, 1] on the wire: round(p x 32768), clamped (NaN: 0). */
uint16_t recruit_wire_quantize(float p);
/* The frame of `msg` into out[0 .. 8]. */
void recruit_wire_encode(const recruit_wire_message *msg, uint8_t out[RECRUIT_WIRE_SIZE]);
/* 0 and *msg filled when in[] is a valid frame; -1 bad sync byte, -2 bad checksum, -3 a
 * probability above 32768. */
int recruit_wire_decode(const uint8_t in[RECRUIT_WIRE_SIZE], recruit_wire_message *msg);
/* CRC-8 (polynomial 0x07, initial value 0, no reflection, no final xor) of n bytes. */
uint8_t recruit_crc8(const uint8_t *data, int n);

/* PCG32 (O'Neill 2014, pcg32_random_r): 64-bit state, 32-bit outputs. */
typedef struct {
  uint64_t state, inc;
} recruit_pcg32;
void recruit_pcg32_seed(recruit_pcg32 *g, uint64_t seed, uint64_t stream);
uint32_t recruit_pcg32_next(recruit_pcg32 *g);

/* One unit: its heater command and its generator. */
typedef struct {
  recruit_pcg32 rng;
  uint8_t bundle;   /* the bundle it belongs to */
  uint8_t on;       /* heater command: 1 on, 0 off */
  uint8_t has_last; /* a frame was taken (last_sequence is valid) */
  uint16_t last_sequence;
} recruit_unit;

/* Off, with its own generator (seed, and a stream that differs between units, e.g. its id). */
void recruit_unit_init(recruit_unit *u, uint8_t bundle, uint64_t seed, uint64_t stream);
/* Takes one received frame: a valid frame for this unit's bundle with a sequence number other
 * than the last one taken draws the transition (an off unit turns on with p_on, an on unit off
 * with p_off: r < q, r the top 15 bits of one draw, q the wire probability). Returns the heater
 * command after the frame (0 or 1), or a negative code (recruit_wire_decode's, or -4 another
 * bundle, -5 a repeated frame) when the frame is ignored. */
int recruit_unit_receive(recruit_unit *u, const uint8_t frame[RECRUIT_WIRE_SIZE]);

#ifdef __cplusplus
}
#endif
#endif /* RECRUIT_UNIT_H */
