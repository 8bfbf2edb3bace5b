/*
 * A simulated 2-DOF pantograph speaking haptic2d's open UDP device protocol, version 2 (and 1)
 * (docs/DEVICE-PROTOCOL.md): the minimal C version for microcontrollers, on POSIX sockets, with
 * its own small SHA-256 and HMAC (FIPS 180-4, RFC 2104; checked against RFC 4231 by --self-test).
 *
 *   cc -O2 -o sim_device devices/udp/sim_device.c -lm
 *   ./sim_device --self-test                       # SHA-256 / HMAC test vectors, exit 0 if right
 *   ./sim_device --bind 127.0.0.1:5005 --key-file udp.key [--pose] [--duration S]
 *                [--rt-priority 70 | --no-rt]
 *   haptic2d run --device udp:127.0.0.1:5005 --device-file my-device.toml --headless --duration 3
 *
 * With --key-file (hex or raw key bytes, mode 600; the host's protocol.key_file) it speaks
 * version 2: a session only for a HELLO with a valid MAC; a command acts only with a valid MAC,
 * the current session and a sequence number newer than the last one acted on; every state is
 * MAC'd. Without a key it speaks version 1 and binds only to a loopback address (with a warning).
 * No valid command for 100 ms: the motors are zeroed (the device's own watchdog).
 *
 * Same device as sim_device.py: the pantograph's end point (devices/udp-pantograph.toml
 * geometry) is a point mass held by a hand (a spring-damper towards the start point); commands
 * (joint torques, f = J^-T tau, or a wrench) are applied until the next one; every command gets
 * one state. On a microcontroller keep pack/unpack and serve(); replace plant_step() and the
 * sampling with your encoders and motor drivers. The first stdout line is
 * `listening on ADDR:PORT`.
 *
 * Real-time priority: on a host computer the device shares the cores with everything else, and at
 * normal priority a loaded machine delays its answers past the host's timeout (a lost device, exit
 * 4). It asks for SCHED_FIFO 70 (--rt-priority P; the host's loop has 80) and locked memory; when
 * the kernel refuses it says so and how to get it, and runs anyway (--no-rt: do not ask).
 * A microcontroller has no other program to wait for: drop realtime() there.
 */
#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <time.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

/* ---- SHA-256 (FIPS 180-4) and HMAC-SHA256 (RFC 2104) ----------------------------------- */
struct sha256 { uint32_t h[8]; uint8_t buf[64]; uint64_t len; size_t fill; };

static const uint32_t K256[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

static uint32_t ror(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

static void sha256_block(struct sha256 *s, const uint8_t *p) {
    uint32_t w[64], v[8];
    for (int i = 0; i < 16; i++)
        w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 |
               (uint32_t)p[4 * i + 2] << 8 | p[4 * i + 3];
    for (int i = 16; i < 64; i++) {
        uint32_t s0 = ror(w[i - 15], 7) ^ ror(w[i - 15], 18) ^ (w[i - 15] >> 3);
        uint32_t s1 = ror(w[i - 2], 17) ^ ror(w[i - 2], 19) ^ (w[i - 2] >> 10);
        w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    memcpy(v, s->h, sizeof v);
    for (int i = 0; i < 64; i++) {
        uint32_t e = v[4], a = v[0];
        uint32_t t1 = v[7] + (ror(e, 6) ^ ror(e, 11) ^ ror(e, 25)) + ((e & v[5]) ^ (~e & v[6])) +
                      K256[i] + w[i];
        uint32_t t2 = (ror(a, 2) ^ ror(a, 13) ^ ror(a, 22)) + ((a & v[1]) ^ (a & v[2]) ^ (v[1] & v[2]));
        memmove(v + 1, v, 7 * sizeof v[0]);
        v[4] += t1;
        v[0] = t1 + t2;
    }
    for (int i = 0; i < 8; i++) s->h[i] += v[i];
}

static void sha256_init(struct sha256 *s) {
    static const uint32_t h0[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                   0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    memcpy(s->h, h0, sizeof h0);
    s->len = 0;
    s->fill = 0;
}

static void sha256_update(struct sha256 *s, const uint8_t *p, size_t n) {
    s->len += n;
    while (n > 0) {
        size_t k = 64 - s->fill < n ? 64 - s->fill : n;
        memcpy(s->buf + s->fill, p, k);
        s->fill += k; p += k; n -= k;
        if (s->fill == 64) { sha256_block(s, s->buf); s->fill = 0; }
    }
}

static void sha256_final(struct sha256 *s, uint8_t out[32]) {
    uint64_t bits = s->len * 8;
    uint8_t pad = 0x80, zero = 0, l[8];
    sha256_update(s, &pad, 1);
    while (s->fill != 56) sha256_update(s, &zero, 1);
    for (int i = 0; i < 8; i++) l[i] = (uint8_t)(bits >> (56 - 8 * i));
    sha256_update(s, l, 8);
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 4; j++) out[4 * i + j] = (uint8_t)(s->h[i] >> (24 - 8 * j));
}

/* HMAC-SHA256 of the concatenation of up to 3 parts (NULL parts skipped). */
static void hmac_sha256(const uint8_t *key, size_t klen, const uint8_t *p1, size_t n1,
                        const uint8_t *p2, size_t n2, const uint8_t *p3, size_t n3,
                        uint8_t out[32]) {
    uint8_t k[64] = {0}, pad[64], inner[32];
    struct sha256 s;
    if (klen > 64) { sha256_init(&s); sha256_update(&s, key, klen); sha256_final(&s, k); }
    else memcpy(k, key, klen);
    for (int i = 0; i < 64; i++) pad[i] = k[i] ^ 0x36;
    sha256_init(&s);
    sha256_update(&s, pad, 64);
    if (p1) sha256_update(&s, p1, n1);
    if (p2) sha256_update(&s, p2, n2);
    if (p3) sha256_update(&s, p3, n3);
    sha256_final(&s, inner);
    for (int i = 0; i < 64; i++) pad[i] = k[i] ^ 0x5c;
    sha256_init(&s);
    sha256_update(&s, pad, 64);
    sha256_update(&s, inner, 32);
    sha256_final(&s, out);
}

static int hexval(int c) {
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
         : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* RFC 4231 test cases 1, 2, 3, 4, 6 and 7 (full 32-byte MACs) and 5 (truncated to 16 bytes). */
static int self_test(void) {
    static const char *want[7] = {
        "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7",
        "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843",
        "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe",
        "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b",
        "a3b6167473100ee06e0c796c2955552b",
        "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54",
        "9b09ffa71b942fcb27635fbcd5b0e944bfdc63644f0713938a7f51535c3a35e2"};
    uint8_t key[131], data[152];
    int bad = 0;
    for (int t = 0; t < 7; t++) {
        size_t kl, dl;
        const char *d = 0;
        switch (t) {
        case 0: kl = 20; memset(key, 0x0b, kl); d = "Hi There"; break;
        case 1: kl = 4; memcpy(key, "Jefe", 4); d = "what do ya want for nothing?"; break;
        case 2: kl = 20; memset(key, 0xaa, kl); dl = 50; memset(data, 0xdd, dl); break;
        case 3: kl = 25; for (int i = 0; i < 25; i++) key[i] = (uint8_t)(i + 1);
                dl = 50; memset(data, 0xcd, dl); break;
        case 4: kl = 20; memset(key, 0x0c, kl); d = "Test With Truncation"; break;
        case 5: kl = 131; memset(key, 0xaa, kl);
                d = "Test Using Larger Than Block-Size Key - Hash Key First"; break;
        default: kl = 131; memset(key, 0xaa, kl);
                d = "This is a test using a larger than block-size key and a larger than "
                    "block-size data. The key needs to be hashed before being used by the "
                    "HMAC algorithm."; break;
        }
        if (d) { dl = strlen(d); memcpy(data, d, dl); }
        uint8_t mac[32];
        hmac_sha256(key, kl, data, dl, NULL, 0, NULL, 0, mac);
        size_t n = strlen(want[t]) / 2;
        for (size_t i = 0; i < n; i++)
            if (mac[i] != (uint8_t)(hexval(want[t][2 * i]) << 4 | hexval(want[t][2 * i + 1]))) {
                printf("RFC 4231 test case %d: wrong\n", t + 1);
                bad = 1;
                break;
            }
    }
    if (!bad) printf("RFC 4231 HMAC-SHA256 test cases 1-7: ok\n");
    return bad;
}

/* ---- protocol v1 ---------------------------------------------------------------------- */
enum { COMMAND_LEN = 44, STATE_LEN = 68 };
/* ---- protocol v2 (authenticated) -------------------------------------------------------- */
enum { MAC_LEN = 16, NONCE_LEN = 16, HEADER2 = 12, KIND_HELLO = 3, KIND_WELCOME = 4 };
enum { HELLO_LEN = HEADER2 + NONCE_LEN + MAC_LEN, WELCOME_LEN = HEADER2 + 2 * NONCE_LEN + MAC_LEN,
       COMMAND2_LEN = HEADER2 + COMMAND_LEN - 4 + MAC_LEN, STATE2_LEN = HEADER2 + STATE_LEN - 4 + MAC_LEN };
enum { FLAG_ENABLE = 1, FLAG_WRENCH = 2, FLAG_LATCHED = 4, FLAG_BYE = 8 };
enum { STATUS_POSE = 1, STATUS_VELOCITY = 2, STATUS_ENABLED = 8, STATUS_LIMITED = 16 };

struct command { uint32_t seq; uint64_t host_ns; uint16_t flags; float c[3]; };

/* Little-endian loads and stores, independent of the host's byte order. */
static uint32_t ld32(const uint8_t *b) {
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}
static uint64_t ld64(const uint8_t *b) { return (uint64_t)ld32(b) | (uint64_t)ld32(b + 4) << 32; }
static void st32(uint8_t *b, uint32_t v) {
    for (int i = 0; i < 4; i++) b[i] = (uint8_t)(v >> (8 * i));
}
static void st64(uint8_t *b, uint64_t v) { st32(b, (uint32_t)v); st32(b + 4, (uint32_t)(v >> 32)); }
static float ldf(const uint8_t *b) { uint32_t u = ld32(b); float f; memcpy(&f, &u, 4); return f; }
static void stf(uint8_t *b, float f) { uint32_t u; memcpy(&u, &f, 4); st32(b, u); }

/* 0 and the fields for a valid v1 command; -1 for anything else (ignored, never answered). */
static int unpack_command(const uint8_t *b, long n, struct command *c) {
    if (n != COMMAND_LEN || b[0] != 'H' || b[1] != '2' || b[2] != 1 || b[3] != 1) return -1;
    c->seq = ld32(b + 4);
    c->host_ns = ld64(b + 8);
    c->flags = (uint16_t)(b[28] | b[29] << 8);
    if ((c->flags & ~15) || b[30] || b[31]) return -1;
    for (int i = 0; i < 3; i++) {
        c->c[i] = ldf(b + 32 + 4 * i);
        if (!isfinite(c->c[i])) return -1;
    }
    return 0;
}

static void pack_state(uint8_t *b, uint32_t seq, uint32_t echo_seq, uint32_t status,
                       uint64_t device_ns, uint64_t echo_host_ns, const float pos[3],
                       const float vel[3]) {
    memset(b, 0, STATE_LEN);
    b[0] = 'H'; b[1] = '2'; b[2] = 1; b[3] = 2;
    st32(b + 4, seq); st32(b + 8, echo_seq); st32(b + 12, status);
    st64(b + 16, device_ns); st64(b + 24, echo_host_ns);
    for (int i = 0; i < 3; i++) { stf(b + 32 + 4 * i, pos[i]); stf(b + 44 + 4 * i, vel[i]); }
}

/* ---- the pantograph (docs/DEVICES.md §2): motor 1 at (0, 0), motor 2 at (d, 0) ------------------ */
static const double D = 0.038, L1 = 0.07, L2 = 0.09;

static void ik(double x, double y, double q[2]) {
    for (int i = 0; i < 2; i++) {
        double rx = x - (i ? D : 0.0), ry = y, rho = hypot(rx, ry);
        double arg = (L1 * L1 + rho * rho - L2 * L2) / (2 * L1 * rho);
        arg = arg < -1 ? -1 : arg > 1 ? 1 : arg;
        double phi = atan2(ry, rx), gamma = acos(arg);
        q[i] = i ? phi - gamma : phi + gamma;
    }
}

/* J = dE/dq at end point (x, y), angles q: U E' = D q', J = U^-1 D. */
static void jacobian(double x, double y, const double q[2], double j[2][2]) {
    double ax = L1 * cos(q[0]), ay = L1 * sin(q[0]);
    double bx = D + L1 * cos(q[1]), by = L1 * sin(q[1]);
    double u1x = x - ax, u1y = y - ay, u2x = x - bx, u2y = y - by;
    double det = u1x * u2y - u1y * u2x;
    double d1 = L1 * (-u1x * sin(q[0]) + u1y * cos(q[0]));
    double d2 = L1 * (-u2x * sin(q[1]) + u2y * cos(q[1]));
    j[0][0] = u2y * d1 / det; j[0][1] = -u1y * d2 / det;
    j[1][0] = -u2x * d1 / det; j[1][1] = u1x * d2 / det;
}

/* x with m x = v. */
static void solve2(double m[2][2], const double v[2], double x[2]) {
    double det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    x[0] = (m[1][1] * v[0] - m[0][1] * v[1]) / det;
    x[1] = (m[0][0] * v[1] - m[1][0] * v[0]) / det;
}

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The plant: end-point mass M held by the hand at (X0, Y0). */
static const double M = 0.15, K_HAND = 200.0, B_HAND = 3.0, TAU_MAX = 0.123, F_MAX = 5.0;
static const double X0 = 0.019, Y0 = 0.10;
static double x = 0.019, y = 0.10, vx, vy, cmd[2];
static int wrench;

static void plant_step(double dt) {
    if (dt > 0.1) dt = 0.1;
    int n = (int)ceil(dt / 0.00025);
    if (n < 1) n = 1;
    double h = dt / n;
    for (int k = 0; k < n; k++) {
        double q[2], j[2][2], f[2] = {cmd[0], cmd[1]};
        if (!wrench) {
            ik(x, y, q);
            jacobian(x, y, q, j);
            double jt[2][2] = {{j[0][0], j[1][0]}, {j[0][1], j[1][1]}};
            solve2(jt, cmd, f); /* J^T f = tau */
        }
        f[0] += K_HAND * (X0 - x) - B_HAND * vx;
        f[1] += K_HAND * (Y0 - y) - B_HAND * vy;
        vx += h * f[0] / M; vy += h * f[1] / M;
        x += h * vx; y += h * vy;
    }
}

/* ---- the device's side of version 2 ----------------------------------------------------- */
static uint8_t key[4096];
static size_t key_len;
static uint64_t active, pending; /* session ids; 0 = none */
static uint32_t last_seq;        /* the newest command seq acted on in the active session */

/* Reads a key file: hex (whitespace ignored, >= 32 digits) or raw bytes; refused when group or
 * others have any permission on it. 0 on success. */
static int read_key(const char *path) {
    struct stat st;
    int fd = open(path, O_RDONLY);
    if (fd < 0 || fstat(fd, &st) != 0) { perror(path); return -1; }
    if (st.st_mode & 077) {
        fprintf(stderr, "error: key file %s is open to group or others (mode %03o); fix: chmod 600 %s\n",
                path, (unsigned)(st.st_mode & 0777), path);
        close(fd);
        return -1;
    }
    uint8_t raw[4096];
    ssize_t n = read(fd, raw, sizeof raw);
    close(fd);
    if (n < 0) { perror(path); return -1; }
    size_t digits = 0, hex = 1;
    for (ssize_t i = 0; i < n; i++) {
        if (raw[i] == ' ' || raw[i] == '\n' || raw[i] == '\r' || raw[i] == '\t') continue;
        if (hexval(raw[i]) < 0) hex = 0;
        digits++;
    }
    if (hex && digits >= 32 && digits % 2 == 0) {
        int hi = -1;
        key_len = 0;
        for (ssize_t i = 0; i < n; i++) {
            int v = hexval(raw[i]);
            if (v < 0) continue;
            if (hi < 0) hi = v; else { key[key_len++] = (uint8_t)(hi << 4 | v); hi = -1; }
        }
    } else {
        memcpy(key, raw, (size_t)n);
        key_len = (size_t)n;
    }
    if (key_len < 16) {
        fprintf(stderr, "error: key file %s: a key of %zu bytes is too short (at least 16)\n", path, key_len);
        return -1;
    }
    return 0;
}

static void mac16(const uint8_t *b, size_t n, uint8_t out[MAC_LEN]) {
    uint8_t full[32];
    hmac_sha256(key, key_len, b, n, NULL, 0, NULL, 0, full);
    memcpy(out, full, MAC_LEN);
}

/* Constant-time check of the MAC at the end of b[0..n). */
static int mac_ok(const uint8_t *b, size_t n) {
    uint8_t m[MAC_LEN], d = 0;
    if (n <= MAC_LEN) return 0;
    mac16(b, n - MAC_LEN, m);
    for (int i = 0; i < MAC_LEN; i++) d |= (uint8_t)(m[i] ^ b[n - MAC_LEN + i]);
    return d == 0;
}

static uint64_t session_id(const uint8_t *hn, const uint8_t *dn) {
    uint8_t full[32];
    hmac_sha256(key, key_len, (const uint8_t *)"H2v2 session", 12, hn, NONCE_LEN, dn, NONCE_LEN, full);
    uint64_t sid = ld64(full);
    return sid ? sid : 1;
}

/* A version-2 datagram: answers a HELLO (returns 0), or, for an authentic, fresh command of the
 * session, rebuilds the v1 command in v1[] and returns 1. Anything else: 0, nothing done. */
static int receive2(int fd, const uint8_t *b, long n, const struct sockaddr *peer, socklen_t plen,
                    uint8_t v1[COMMAND_LEN]) {
    if (n < HEADER2 + MAC_LEN || b[0] != 'H' || b[1] != '2' || b[2] != 2) return 0;
    if (!mac_ok(b, (size_t)n)) return 0; /* verify before acting */
    uint64_t sid = ld64(b + 4);
    if (b[3] == KIND_HELLO && n == HELLO_LEN && sid == 0) {
        uint8_t w[WELCOME_LEN], dn[NONCE_LEN];
        int r = open("/dev/urandom", O_RDONLY);
        if (r < 0 || read(r, dn, NONCE_LEN) != NONCE_LEN) { if (r >= 0) close(r); return 0; }
        close(r);
        pending = session_id(b + HEADER2, dn);
        w[0] = 'H'; w[1] = '2'; w[2] = 2; w[3] = KIND_WELCOME;
        st64(w + 4, pending);
        memcpy(w + HEADER2, b + HEADER2, NONCE_LEN);
        memcpy(w + HEADER2 + NONCE_LEN, dn, NONCE_LEN);
        mac16(w, WELCOME_LEN - MAC_LEN, w + WELCOME_LEN - MAC_LEN);
        sendto(fd, w, WELCOME_LEN, 0, peer, plen);
        return 0;
    }
    if (b[3] != 1 || n != COMMAND2_LEN) return 0;
    if (pending && sid == pending) { active = pending; pending = 0; last_seq = 0; }
    else if (!active || sid != active) return 0; /* another session's */
    uint32_t seq = ld32(b + HEADER2);
    if (seq <= last_seq) return 0; /* stale or replayed */
    v1[0] = 'H'; v1[1] = '2'; v1[2] = 1; v1[3] = 1;
    memcpy(v1 + 4, b + HEADER2, COMMAND_LEN - 4);
    struct command c;
    if (unpack_command(v1, COMMAND_LEN, &c) != 0) return 0;
    last_seq = seq;
    return 1;
}

/* SCHED_FIFO `prio` and locked memory for this process; prints what it got on stderr, and how to
 * get it when refused. */
static void realtime(int prio) {
    if (prio <= 0) {
        fprintf(stderr, "sim_device: normal priority (--no-rt): on a loaded machine its answers come "
                        "late and the host may stop with a lost device\n");
        return;
    }
    struct sched_param sp = {0};
    sp.sched_priority = prio;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
        fprintf(stderr,
                "warning: sim_device runs without real-time priority (SCHED_FIFO %d refused: needs "
                "CAP_SYS_NICE or `ulimit -r %d`): on a loaded machine its answers come late and the "
                "host may stop with a lost device (exit 4)\n    fix: run it as root, or `sudo setcap "
                "cap_sys_nice,cap_ipc_lock+ep ./sim_device`, or raise the rtprio limit (`ulimit -r "
                "%d`), or start it with `sudo chrt -f %d ./sim_device ...`\n",
                prio, prio, prio, prio);
        return;
    }
    int locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
    fprintf(stderr, "sim_device: real-time priority SCHED_FIFO %d%s\n", prio,
            locked ? ", memory locked" : " (memory not locked)");
}

int main(int argc, char **argv) {
    const char *bind_arg = "127.0.0.1:5005";
    const char *key_file = NULL;
    FILE *trace = NULL;
    int pose = 0, rt_prio = 70;
    double duration = 0, watchdog_s = 0.1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--bind") && i + 1 < argc) bind_arg = argv[++i];
        else if (!strcmp(argv[i], "--pose")) pose = 1;
        else if (!strcmp(argv[i], "--duration") && i + 1 < argc) duration = atof(argv[++i]);
        else if (!strcmp(argv[i], "--key-file") && i + 1 < argc) key_file = argv[++i];
        else if (!strcmp(argv[i], "--rt-priority") && i + 1 < argc) {
            rt_prio = atoi(argv[++i]);
            if (rt_prio < 1 || rt_prio > 99) {
                fprintf(stderr, "error: --rt-priority %s: expected 1-99 (default 70)\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(argv[i], "--no-rt")) rt_prio = 0;
        else if (!strcmp(argv[i], "--trace") && i + 1 < argc) {
            trace = fopen(argv[++i], "w");
            if (!trace) { perror(argv[i]); return 1; }
        } else if (!strcmp(argv[i], "--self-test")) return self_test();
        else {
            fprintf(stderr, "usage: %s [--bind ADDR:PORT] [--key-file KEY] [--pose] [--duration S] "
                            "[--rt-priority P | --no-rt] [--trace FILE] | --self-test\n", argv[0]);
            return 2;
        }
    }
    if (key_file && read_key(key_file) != 0) return 2;
    char host[64];
    const char *colon = strrchr(bind_arg, ':');
    if (!colon || (size_t)(colon - bind_arg) >= sizeof host) {
        fprintf(stderr, "error: --bind %s: expected IPV4:PORT\n", bind_arg);
        return 2;
    }
    memcpy(host, bind_arg, (size_t)(colon - bind_arg));
    host[colon - bind_arg] = 0;
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)atoi(colon + 1));
    if (inet_pton(AF_INET, host, &a.sin_addr) != 1) {
        fprintf(stderr, "error: --bind %s: `%s` is not an IPv4 address\n", bind_arg, host);
        return 2;
    }
    if (!key_file) {
        if ((ntohl(a.sin_addr.s_addr) >> 24) != 127) {
            fprintf(stderr, "error: --bind %s: protocol version 1 (no --key-file) is unauthenticated "
                            "and allowed on loopback only; give --key-file\n", bind_arg);
            return 2;
        }
        fprintf(stderr, "warning: protocol version 1 (no --key-file): any local process can "
                        "command this device\n");
    }
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) < 0) {
        perror("error: bind");
        return 1;
    }
    realtime(rt_prio);
    socklen_t alen = sizeof a;
    getsockname(fd, (struct sockaddr *)&a, &alen);
    char shown[64];
    inet_ntop(AF_INET, &a.sin_addr, shown, sizeof shown);
    printf("listening on %s:%u\n", shown, ntohs(a.sin_port));
    fflush(stdout);
    struct timeval tv = {0, 10000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);

    double t0 = now_s(), t_last = t0, last_cmd = -1;
    uint32_t seq = 0;
    uint8_t in[256], out[STATE_LEN], v1[COMMAND_LEN], out2[STATE2_LEN];
    while (duration <= 0 || now_s() - t0 < duration) {
        struct sockaddr_storage peer;
        socklen_t plen = sizeof peer;
        long n = recvfrom(fd, in, sizeof in, 0, (struct sockaddr *)&peer, &plen);
        double t = now_s();
        if (last_cmd >= 0 && t - last_cmd > watchdog_s && (cmd[0] != 0 || cmd[1] != 0)) {
            cmd[0] = cmd[1] = 0; /* device watchdog: no valid command for 100 ms */
            if (trace) { fprintf(trace, "watchdog 0 0\n"); fflush(trace); }
        }
        struct command c;
        if (n < 0) continue;
        const uint8_t *body = in;
        long blen = n;
        if (key_file) {
            if (!receive2(fd, in, n, (struct sockaddr *)&peer, plen, v1)) continue;
            body = v1;
            blen = COMMAND_LEN;
        }
        if (unpack_command(body, blen, &c) != 0) continue;
        plant_step(t - t_last);
        t_last = last_cmd = t;
        int enabled = (c.flags & FLAG_ENABLE) && !(c.flags & (FLAG_LATCHED | FLAG_BYE));
        wrench = (c.flags & FLAG_WRENCH) != 0;
        double lim = wrench ? F_MAX : TAU_MAX;
        uint32_t status = STATUS_VELOCITY | (enabled ? STATUS_ENABLED : 0);
        for (int i = 0; i < 2; i++) {
            double v = enabled ? c.c[i] : 0.0;
            if (fabs(v) > lim) { v = v > 0 ? lim : -lim; status |= STATUS_LIMITED; }
            cmd[i] = v;
        }
        double q[2], j[2][2], qd[2], v[2] = {vx, vy};
        ik(x, y, q);
        jacobian(x, y, q, j);
        solve2(j, v, qd);
        float pos[3] = {(float)q[0], (float)q[1], 0}, vel[3] = {(float)qd[0], (float)qd[1], 0};
        if (pose) {
            status |= STATUS_POSE;
            pos[0] = (float)x; pos[1] = (float)y;
            vel[0] = (float)vx; vel[1] = (float)vy;
        }
        pack_state(out, ++seq, c.seq, status, (uint64_t)((t - t0) * 1e9), c.host_ns, pos, vel);
        if (key_file) {
            out2[0] = 'H'; out2[1] = '2'; out2[2] = 2; out2[3] = 2;
            st64(out2 + 4, active);
            memcpy(out2 + HEADER2, out + 4, STATE_LEN - 4);
            mac16(out2, STATE2_LEN - MAC_LEN, out2 + STATE2_LEN - MAC_LEN);
            sendto(fd, out2, STATE2_LEN, 0, (struct sockaddr *)&peer, plen);
        } else {
            sendto(fd, out, STATE_LEN, 0, (struct sockaddr *)&peer, plen);
        }
        if (trace) { fprintf(trace, "applied %.6f %.6f\n", cmd[0], cmd[1]); fflush(trace); }
    }
    return 0;
}
