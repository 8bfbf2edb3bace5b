/* The native build of the haptic2d firmware: the Arduino calls of board.c, the serial port as a
 * pseudo-terminal, and a log of every change of the motor outputs.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 *   h2df-native [--motor-log FILE]          (or the environment variable H2DF_MOTOR_LOG=FILE)
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
 * The encoders are static: no interrupt ever fires, so the handle stays where the last setup put
 * it (the rest pose) and every angle reads trunc(offset·resolution/360)·360/resolution.
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
    /* Static encoders: the handle never moves, no edge ever comes. */
    (void)pin;
    (void)callback;
    (void)mode;
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
        } else {
            fprintf(stderr, "usage: %s [--motor-log FILE]\n", argv[0]);
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
        h2df_poll(&fw);
        /* Idle until a byte comes, at most 200 µs (the watchdog's check interval while idle). */
        struct pollfd pfd = {.fd = master, .events = POLLIN};
        struct timespec wait = {.tv_sec = 0, .tv_nsec = 200000};
        if (rx_at == rx_len) {
            (void)ppoll(&pfd, 1, &wait, NULL);
        }
    }
}
