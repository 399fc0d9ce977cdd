/* A controller for `recruit sil` (docs/sil.md): the package `recruit export` writes, built for
 * the host, closing the loop over UDP or a pseudo-terminal. It says hello, answers each
 * measurement frame with a command frame from recruit_step, and exits on the end frame.
 *
 *   cc -std=c99 -O2 -I PKG sil_controller.c PKG/recruit_controller.c -lm -o sil_controller
 *   recruit sil --task T --port 47000 &        # prints: listening on udp 127.0.0.1:47000
 *   ./sil_controller --udp 127.0.0.1:47000 --dT 1
 *   recruit sil --task T --link pty --pty-link /tmp/plant &
 *   ./sil_controller --pty /tmp/plant --dT 1
 *
 * For the tests, faults can be injected at one control instant K each: --skip K (no answer),
 * --late K (K's answer sent after the next measurement), --corrupt K (a copy with one bit
 * flipped first), --truncate K (a copy cut short first), --oversize K (a copy with bytes
 * appended first), --replay K (the answer sent twice), --junk K (random bytes first).
 * Exit: 0 after the end frame, 1 on bad arguments or a failed link, 2 when the plant closed the
 * pseudo-terminal without one, 3 when the plant is silent for --timeout seconds (default 15). */
#define _DEFAULT_SOURCE
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include "recruit_controller.h"

#define SYNC 0x5A
#define HEADER 7
#define MAX_FRAME (HEADER + 5 * 8 * 8 + 2)

/* ---- the protocol (docs/sil.md) ---- */

static uint16_t crc16(const uint8_t *d, size_t n) { /* CRC-16/CCITT-FALSE */
  uint16_t crc = 0xFFFF;
  size_t i;
  int b;
  for (i = 0; i < n; ++i) {
    crc ^= (uint16_t)(d[i] << 8);
    for (b = 0; b < 8; ++b)
      crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
  }
  return crc;
}

static size_t header(uint8_t *f, char type, uint32_t seq) {
  int i;
  f[0] = SYNC;
  f[1] = (uint8_t)type;
  f[2] = RECRUIT_NUM_BUNDLES;
  for (i = 0; i < 4; ++i) f[3 + i] = (uint8_t)(seq >> (8 * i));
  return HEADER;
}

static size_t put_double(uint8_t *f, size_t at, double v) {
  uint64_t u;
  int i;
  memcpy(&u, &v, sizeof u);
  for (i = 0; i < 8; ++i) f[at + i] = (uint8_t)(u >> (8 * i));
  return at + 8;
}

static double get_double(const uint8_t *p) {
  uint64_t u = 0;
  double v;
  int i;
  for (i = 0; i < 8; ++i) u |= (uint64_t)p[i] << (8 * i);
  memcpy(&v, &u, sizeof v);
  return v;
}

static size_t seal(uint8_t *f, size_t n) {
  uint16_t c = crc16(f, n);
  f[n] = (uint8_t)(c & 0xFF);
  f[n + 1] = (uint8_t)(c >> 8);
  return n + 2;
}

/* Size of the frame whose header starts at p (3 bytes known), 0 if not a frame header. */
static size_t frame_size(const uint8_t *p) {
  size_t values;
  if (p[0] != SYNC || p[2] < 1 || p[2] > 8) return 0;
  switch (p[1]) {
    case 'H':
      values = 1;
      break;
    case 'E':
      values = 0;
      break;
    case 'M':
      values = 4 + 2 * (size_t)p[2];
      break;
    case 'C':
      values = 5 * (size_t)p[2];
      break;
    default:
      return 0;
  }
  return HEADER + 8 * values + 2;
}

static int valid(const uint8_t *p, size_t n) {
  return n >= HEADER + 2 && frame_size(p) == n &&
         crc16(p, n - 2) == (uint16_t)(p[n - 2] | (p[n - 1] << 8));
}

/* ---- the link ---- */

static int fd = -1, is_pty = 0;
static uint8_t rx[4096];
static size_t rx_len = 0;

static void send_bytes(const uint8_t *f, size_t n) {
  if (is_pty) {
    size_t done = 0;
    while (done < n) {
      ssize_t w = write(fd, f + done, n - done);
      if (w <= 0) exit(1);
      done += (size_t)w;
    }
  } else {
    (void)send(fd, f, n, 0);
  }
}

/* The next valid frame into f (its size), waiting at most timeout_ms; 0 on silence. */
static size_t receive(uint8_t *f, int timeout_ms) {
  for (;;) {
    struct pollfd p;
    ssize_t n;
    if (is_pty) { /* find a frame in the stream, skipping what is not one */
      size_t s = 0;
      while (s < rx_len) {
        size_t want;
        if (rx[s] != SYNC) {
          ++s;
          continue;
        }
        if (rx_len - s < 3) break;
        want = frame_size(rx + s);
        if (want == 0) {
          ++s;
          continue;
        }
        if (rx_len - s < want) break;
        if (valid(rx + s, want)) {
          memcpy(f, rx + s, want);
          memmove(rx, rx + s + want, rx_len - s - want);
          rx_len -= s + want;
          return want;
        }
        ++s;
      }
      memmove(rx, rx + s, rx_len - s);
      rx_len -= s;
    }
    p.fd = fd;
    p.events = POLLIN;
    p.revents = 0;
    if (poll(&p, 1, timeout_ms) <= 0) return 0;
    if (is_pty) {
      n = read(fd, rx + rx_len, sizeof rx - rx_len);
      if (n <= 0) { /* the plant closed the pseudo-terminal (EIO or end of file) */
        fprintf(stderr, "sil_controller: the link was closed\n");
        exit(2);
      }
      rx_len += (size_t)n;
    } else {
      n = recv(fd, f, MAX_FRAME, 0);
      if (n > 0 && valid(f, (size_t)n)) return (size_t)n;
    }
  }
}

static void open_udp(const char *spec) {
  struct sockaddr_in a;
  char host[64];
  const char *colon = strrchr(spec, ':');
  if (colon == NULL || (size_t)(colon - spec) >= sizeof host) exit(1);
  memcpy(host, spec, (size_t)(colon - spec));
  host[colon - spec] = '\0';
  memset(&a, 0, sizeof a);
  a.sin_family = AF_INET;
  a.sin_port = htons((uint16_t)atoi(colon + 1));
  if (inet_pton(AF_INET, host, &a.sin_addr) != 1) exit(1);
  fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) exit(1);
}

static void open_pty(const char *path) {
  struct termios t;
  fd = open(path, O_RDWR | O_NOCTTY);
  if (fd < 0) exit(1);
  if (tcgetattr(fd, &t) == 0) {
    cfmakeraw(&t);
    tcsetattr(fd, TCSANOW, &t);
  }
  is_pty = 1;
}

/* ---- the loop ---- */

int main(int argc, char **argv) {
  static recruit_controller ctl;
  long skip = -1, late = -1, corrupt = -1, truncate_at = -1, oversize = -1, replay = -1, junk = -1;
  double dT = 0, timeout = 15;
  uint8_t f[MAX_FRAME + 16], held[MAX_FRAME];
  size_t held_n = 0;
  int i;
  for (i = 1; i + 1 < argc; i += 2) {
    const char *k = argv[i], *v = argv[i + 1];
    if (!strcmp(k, "--udp"))
      open_udp(v);
    else if (!strcmp(k, "--pty"))
      open_pty(v);
    else if (!strcmp(k, "--dT"))
      dT = atof(v);
    else if (!strcmp(k, "--timeout"))
      timeout = atof(v);
    else if (!strcmp(k, "--skip"))
      skip = atol(v);
    else if (!strcmp(k, "--late"))
      late = atol(v);
    else if (!strcmp(k, "--corrupt"))
      corrupt = atol(v);
    else if (!strcmp(k, "--truncate"))
      truncate_at = atol(v);
    else if (!strcmp(k, "--oversize"))
      oversize = atol(v);
    else if (!strcmp(k, "--replay"))
      replay = atol(v);
    else if (!strcmp(k, "--junk"))
      junk = atol(v);
    else {
      fprintf(stderr, "sil_controller: unknown option %s\n", k);
      return 1;
    }
  }
  if (fd < 0) {
    fprintf(stderr, "sil_controller: give --udp HOST:PORT or --pty PATH\n");
    return 1;
  }
  recruit_init(&ctl);
  send_bytes(f, seal(f, put_double(f, header(f, 'H', 0), dT)));
  for (;;) {
    recruit_input in;
    recruit_output out;
    uint8_t c[MAX_FRAME + 16];
    size_t n = receive(f, (int)(timeout * 1000)), at;
    uint32_t k;
    if (n == 0) {
      fprintf(stderr, "sil_controller: the plant is silent\n");
      return 3;
    }
    if (f[1] == 'E') return 0;
    if (f[1] != 'M') continue;
    k = (uint32_t)f[3] | (uint32_t)f[4] << 8 | (uint32_t)f[5] << 16 | (uint32_t)f[6] << 24;
    in.reference = (recruit_real)get_double(f + HEADER + 8);
    in.angle = (recruit_real)get_double(f + HEADER + 16);
    in.angular_velocity = (recruit_real)get_double(f + HEADER + 24);
    for (i = 0; i < RECRUIT_NUM_BUNDLES; ++i) {
      in.force[i] = (recruit_real)get_double(f + HEADER + 32 + 8 * i);
      in.length[i] = (recruit_real)get_double(f + HEADER + 32 + 8 * (RECRUIT_NUM_BUNDLES + i));
    }
    recruit_step(&ctl, &in, &out);
    at = header(c, 'C', k);
    for (i = 0; i < RECRUIT_NUM_BUNDLES; ++i) {
      at = put_double(c, at, out.force_reference[i]);
      at = put_double(c, at, out.p_on[i]);
      at = put_double(c, at, out.p_off[i]);
      at = put_double(c, at, out.estimated_on[i]);
      at = put_double(c, at, out.variance[i]);
    }
    n = seal(c, at);
    if ((long)k == junk) {
      uint8_t j[23];
      for (i = 0; i < 23; ++i) j[i] = (uint8_t)(37 * i + 11);
      send_bytes(j, 23);
    }
    if ((long)k == corrupt) {
      c[HEADER + 3] ^= 0x10;
      send_bytes(c, n);
      c[HEADER + 3] ^= 0x10;
    }
    if ((long)k == truncate_at) send_bytes(c, n - 5);
    if ((long)k == oversize) {
      memset(c + n, 0, 16);
      send_bytes(c, n + 16);
    }
    if ((long)k == skip) continue;
    if ((long)k == late) {
      memcpy(held, c, n);
      held_n = n;
      continue;
    }
    send_bytes(c, n);
    if (held_n > 0) {
      send_bytes(held, held_n);
      held_n = 0;
    }
    if ((long)k == replay) send_bytes(c, n);
  }
}
