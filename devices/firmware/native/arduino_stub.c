/* The native build of the haptic2d firmware: the Arduino calls of board.c, the serial port as a
 * pseudo-terminal, and a log of every change of the motor outputs.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 *   h2df-native [--motor-log FILE] [--hand-move START_MS,DURATION_MS,C1,C2,C3,C4]
 *
 * (the motor log may also be given as the environment variable H2DF_MOTOR_LOG=FILE).
 *
 * The first line of standard output is `pty: /dev/pts/N`: open it as the board's serial port.
 * The slave side is held open here, so the firmware keeps running (as a board does) when a host
 * closes the port or dies.
 *
 * The motor log is text, one event per line, flushed at once (a test reads it while this runs):
 *
 *   # comment lines
 *   M <t_us> <duty1> <duty2> <duty3> <duty4> <tau1> <tau2> <tau3> <tau4>
 *   E <t_us> <reset|setup|write|identify|watchdog|bad-byte|stale-frame>
 *
 * An M line is written whenever the PWM or direction pins of a port change: duty k is the PWM
 * duty of port k as the pins carry it (negative while the direction pin is low), tau k the
 * torque it stands for (duty / H2DF_DUTY_MAX · 0.123 N·m, same sign). t_us is CLOCK_MONOTONIC in
 * µs since the program started. An E line tells what the firmware did (`write` after the write's
 * motor outputs were set).
 *
 * The encoders: the handle is held by a simulated hand, kinematically (the motors do not move it).
 * Without --hand-move it stays where the last setup put it (the rest pose): every angle reads
 * trunc(offset·resolution/360)·360/resolution. With --hand-move, START_MS after each setup the hand
 * moves encoder port k (port 1 first) by Ck counts at a steady rate over DURATION_MS, then holds it
 * there: the stub turns the motion into A/B quadrature edges on the encoder pins and calls the
 * interrupt handlers board.c attached, so the board's own decoder counts them.
 * analogRead(pin) returns 4·pin. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "Arduino.h"
#include "board_pins.h"
#include "h2df.h"
#include "h2df_hal.h"

#define NPINS 128

static int master = -1;
static FILE *motor_log;
static struct timespec t0;
static uint32_t pwm_level[NPINS];
static uint8_t dig_level[NPINS];
static int write_bits = 8;
static long logged[4];
static bool logged_any;
static const uint8_t port_pwm[4] = H2DF_PINS_PWM;
static const uint8_t port_dir[4] = H2DF_PINS_DIR;
static const uint8_t port_enc_a[4] = H2DF_PINS_ENC_A;
static const uint8_t port_enc_b[4] = H2DF_PINS_ENC_B;
static void (*isr_of_pin[NPINS])(void);

/* The simulated hand: encoder positions (counts), the move after each setup. */
static long enc_pos[4];
static long enc_pos_at_setup[4];
static uint64_t t_setup_us;
static bool hand_moves, hand_armed; /* armed by the first setup */
static long hand_start_ms, hand_duration_ms, hand_counts[4];

static uint64_t now_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)(t.tv_sec - t0.tv_sec) * 1000000u + (uint64_t)(t.tv_nsec / 1000) -
           (uint64_t)(t0.tv_nsec / 1000);
}

/* ---- Arduino calls ---- */

void pinMode(uint32_t pin, uint32_t mode)
{
    (void)pin;
    (void)mode;
}

static void log_motors(void)
{
    long duty[4] = {0, 0, 0, 0};
    bool changed = !logged_any;
    for (unsigned p = 0; p < H2DF_PORTS; p++) {
        long d = (long)pwm_level[port_pwm[p]];
        duty[p] = dig_level[port_dir[p]] ? d : -d;
        changed = changed || duty[p] != logged[p];
    }
    if (!changed || !motor_log) return;
    fprintf(motor_log, "M %llu", (unsigned long long)now_us());
    for (unsigned p = 0; p < 4; p++) fprintf(motor_log, " %ld", duty[p]);
    for (unsigned p = 0; p < 4; p++) {
        fprintf(motor_log, " %.6f", (double)duty[p] / (double)H2DF_DUTY_MAX * (double)H2DF_TORQUE_LIMIT);
    }
    fputc('\n', motor_log);
    fflush(motor_log);
    memcpy(logged, duty, sizeof logged);
    logged_any = true;
}

void digitalWrite(uint32_t pin, uint32_t value)
{
    if (pin >= NPINS) return;
    dig_level[pin] = value ? 1 : 0;
    log_motors();
}

int digitalRead(uint32_t pin)
{
    return pin < NPINS ? dig_level[pin] : 0;
}

int analogRead(uint32_t pin)
{
    return (int)(4 * pin);
}

void analogWrite(uint32_t pin, uint32_t value)
{
    if (pin >= NPINS) return;
    uint32_t max = (1u << write_bits) - 1u;
    pwm_level[pin] = value > max ? max : value;
    log_motors();
}

void analogWriteResolution(int bits)
{
    write_bits = bits;
}

unsigned long micros(void)
{
    return (unsigned long)(uint32_t)now_us();
}

unsigned long millis(void)
{
    return (unsigned long)(uint32_t)(now_us() / 1000u);
}

void attachInterrupt(uint32_t pin, void (*callback)(void), uint32_t mode)
{
    (void)mode; /* CHANGE: every edge of the pin */
    if (pin < NPINS) isr_of_pin[pin] = callback;
}

/* A/B levels of encoder position n: 00, 01, 11, 10, ... (one pin changes per count). */
static void quad_levels(long n, uint8_t *a, uint8_t *b)
{
    static const uint8_t gray[4] = {0u, 1u, 3u, 2u};
    uint8_t g = gray[((n % 4) + 4) % 4];
    *a = (uint8_t)(g >> 1);
    *b = (uint8_t)(g & 1u);
}

/* Moves encoder `port` one count towards `dir` (+1/-1): the pin that changes, then its interrupt. */
static void enc_step(unsigned port, int dir)
{
    uint8_t a0, b0, a1, b1;
    quad_levels(enc_pos[port], &a0, &b0);
    enc_pos[port] += dir;
    quad_levels(enc_pos[port], &a1, &b1);
    uint8_t pin = a1 != a0 ? port_enc_a[port] : port_enc_b[port];
    dig_level[port_enc_a[port]] = a1;
    dig_level[port_enc_b[port]] = b1;
    if (isr_of_pin[pin]) isr_of_pin[pin]();
}

/* The hand: where each encoder should be now; the edges to get there. */
static void hand_update(void)
{
    if (!hand_moves || !hand_armed) return;
    double t_ms = (double)(now_us() - t_setup_us) / 1000.0;
    double f = (t_ms - (double)hand_start_ms) / (double)(hand_duration_ms > 0 ? hand_duration_ms : 1);
    f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
    for (unsigned p = 0; p < H2DF_PORTS; p++) {
        long target = enc_pos_at_setup[p] + (long)((double)hand_counts[p] * f);
        while (enc_pos[p] != target) enc_step(p, target > enc_pos[p] ? 1 : -1);
    }
}

void noInterrupts(void) {}

void interrupts(void) {}

/* ---- the sketch's serial port, on the pseudo-terminal ---- */

static uint8_t rx_buf[256];
static size_t rx_len, rx_at;

int h2df_serial_available(void)
{
    if (rx_at == rx_len) {
        rx_at = rx_len = 0;
        ssize_t n = read(master, rx_buf, sizeof rx_buf);
        if (n > 0) rx_len = (size_t)n;
    }
    return (int)(rx_len - rx_at);
}

int h2df_serial_read(void)
{
    if (h2df_serial_available() == 0) return -1;
    return rx_buf[rx_at++];
}

void h2df_serial_write(const uint8_t *bytes, size_t n)
{
    while (n > 0) {
        ssize_t k = write(master, bytes, n);
        if (k > 0) {
            bytes += k;
            n -= (size_t)k;
        } else if (k < 0 && (errno == EAGAIN || errno == EINTR)) {
            struct pollfd pfd = {.fd = master, .events = POLLOUT};
            (void)poll(&pfd, 1, 1);
        } else {
            return; /* as a USB port with nobody listening: the bytes are lost */
        }
    }
}

void h2df_hal_event(uint8_t event)
{
    if (event == H2DF_EV_SETUP) {
        /* The setup put the handle at the rest pose: the hand starts from here. */
        memcpy(enc_pos_at_setup, enc_pos, sizeof enc_pos);
        t_setup_us = now_us();
        hand_armed = true;
    }
    static const char *const names[] = {"reset", "setup", "write", "identify", "watchdog",
                                        "bad-byte", "stale-frame"};
    if (!motor_log || event >= sizeof names / sizeof names[0]) return;
    fprintf(motor_log, "E %llu %s\n", (unsigned long long)now_us(), names[event]);
    fflush(motor_log);
}

/* ---- main ---- */

static int open_pty(char *path, size_t cap, int *keep)
{
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0) return -1;
    const char *name = ptsname(m);
    if (!name || strlen(name) >= cap) return -1;
    strcpy(path, name);
    /* Hold the slave open (the master never sees a hang-up) and put the line in raw mode. */
    *keep = open(path, O_RDWR | O_NOCTTY);
    if (*keep < 0) return -1;
    struct termios t;
    if (tcgetattr(*keep, &t) != 0) return -1;
    cfmakeraw(&t);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    if (tcsetattr(*keep, TCSANOW, &t) != 0) return -1;
    int fl = fcntl(m, F_GETFL);
    if (fl < 0 || fcntl(m, F_SETFL, fl | O_NONBLOCK) != 0) return -1;
    return m;
}

int main(int argc, char **argv)
{
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const char *log_path = getenv("H2DF_MOTOR_LOG");
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--motor-log") == 0 && i + 1 < argc) {
            log_path = argv[++i];
        } else if (strcmp(argv[i], "--hand-move") == 0 && i + 1 < argc &&
                   sscanf(argv[i + 1], "%ld,%ld,%ld,%ld,%ld,%ld", &hand_start_ms,
                          &hand_duration_ms, &hand_counts[0], &hand_counts[1], &hand_counts[2],
                          &hand_counts[3]) >= 3) {
            hand_moves = true;
            i++;
        } else {
            fprintf(stderr,
                    "usage: %s [--motor-log FILE] [--hand-move START_MS,DURATION_MS,C1,C2,C3,C4]\n",
                    argv[0]);
            return 2;
        }
    }
    if (log_path && *log_path) {
        motor_log = fopen(log_path, "w");
        if (!motor_log) {
            fprintf(stderr, "cannot write the motor log %s: %s\n", log_path, strerror(errno));
            return 1;
        }
        fprintf(motor_log,
                "# haptic2d firmware (native build), board %s: %u ports, duty max %u, "
                "%.3f N*m at full duty\n",
                H2DF_BOARD_NAME, (unsigned)H2DF_PORTS, (unsigned)H2DF_DUTY_MAX,
                (double)H2DF_TORQUE_LIMIT);
        fprintf(motor_log, "# M t_us duty1 duty2 duty3 duty4 tau1 tau2 tau3 tau4 | E t_us event\n");
        fflush(motor_log);
    }
    char path[128];
    int keep = -1;
    master = open_pty(path, sizeof path, &keep);
    if (master < 0) {
        fprintf(stderr, "cannot create a pseudo-terminal: %s\n", strerror(errno));
        return 1;
    }

    static struct h2df fw;
    h2df_init(&fw); /* power-up: every motor output zero (logged) */
    printf("pty: %s\n", path);
    fflush(stdout);

    for (;;) {
        hand_update();
        h2df_poll(&fw);
        /* Idle until a byte comes, at most 200 µs (the watchdog's check interval while idle). */
        struct pollfd pfd = {.fd = master, .events = POLLIN};
        struct timespec wait = {.tv_sec = 0, .tv_nsec = 200000};
        if (rx_at == rx_len) {
            (void)ppoll(&pfd, 1, &wait, NULL);
        }
    }
}
