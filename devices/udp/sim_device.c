/*
 * A simulated 2-DOF pantograph speaking haptic2d's open UDP device protocol, version 1
 * (docs/DEVICE-PROTOCOL.md): the minimal C version for microcontrollers, on POSIX sockets.
 *
 *   cc -O2 -o sim_device devices/udp/sim_device.c -lm
 *   ./sim_device --bind 127.0.0.1:5005 [--pose] [--duration S]
 *   haptic2d run --device udp:127.0.0.1:5005 --headless --duration 3
 *
 * Same device as sim_device.py: the pantograph's end point (devices/udp-pantograph.toml
 * geometry) is a point mass held by a hand (a spring-damper towards the start point); commands
 * (joint torques, f = J^-T tau, or a wrench) are applied until the next one; every command gets
 * one state. On a microcontroller keep pack/unpack and serve(); replace plant_step() and the
 * sampling with your encoders and motor drivers. The first stdout line is
 * `listening on ADDR:PORT`.
 */
#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>

/* ---- protocol v1 ---------------------------------------------------------------------- */
enum { COMMAND_LEN = 44, STATE_LEN = 68 };
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

int main(int argc, char **argv) {
    const char *bind_arg = "127.0.0.1:5005";
    int pose = 0;
    double duration = 0, watchdog_s = 0.1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--bind") && i + 1 < argc) bind_arg = argv[++i];
        else if (!strcmp(argv[i], "--pose")) pose = 1;
        else if (!strcmp(argv[i], "--duration") && i + 1 < argc) duration = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--bind ADDR:PORT] [--pose] [--duration S]\n", argv[0]);
            return 2;
        }
    }
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
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) < 0) {
        perror("error: bind");
        return 1;
    }
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
    uint8_t in[256], out[STATE_LEN];
    while (duration <= 0 || now_s() - t0 < duration) {
        struct sockaddr_storage peer;
        socklen_t plen = sizeof peer;
        long n = recvfrom(fd, in, sizeof in, 0, (struct sockaddr *)&peer, &plen);
        double t = now_s();
        if (last_cmd >= 0 && t - last_cmd > watchdog_s) cmd[0] = cmd[1] = 0; /* device watchdog */
        struct command c;
        if (n < 0 || unpack_command(in, n, &c) != 0) continue;
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
        sendto(fd, out, STATE_LEN, 0, (struct sockaddr *)&peer, plen);
    }
    return 0;
}
