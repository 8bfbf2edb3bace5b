/* haptic2d firmware for Haply M0/M3 boards: the board-independent core (see h2df.h).
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * Safety beyond the stock protocol:
 *   - every motor output is zero at power-up, after every setup and after every reset;
 *   - |τ| ≤ 0.123 N·m on the board, a non-finite torque is zero;
 *   - a watchdog: when no write has arrived for watchdog_ms (default 20 ms), every motor output
 *     goes to zero until the next write;
 *   - a setup that names ports the board lacks drives and reports only the ports it has (the reply
 *     is shorter than the host asked: the host sees it at once);
 *   - a setup with more than 12 analog pins or 4 PWM pins is garbage, not a setup: its first byte
 *     is skipped like any unknown byte (never configure motors from garbage). */
#include "h2df.h"

#include <string.h>

#include "h2df_hal.h"

/* f32 little-endian from the wire (both SAMD and x86-64 are little-endian, as the wire is). */
static float get_f32(const uint8_t *b)
{
    float v;
    memcpy(&v, b, sizeof v);
    return v;
}

static void put_f32(uint8_t *b, float v)
{
    memcpy(b, &v, sizeof v);
}

static uint8_t popcount4(uint8_t mask)
{
    uint8_t n = 0;
    for (uint8_t i = 0; i < H2DF_WIRE_PORTS; i++) {
        n = (uint8_t)(n + ((mask >> i) & 1u));
    }
    return n;
}

static bool finite_f32(float v)
{
    /* No libm: NaN fails v == v, ±inf fails the range check. */
    return v == v && v <= 3.4e38f && v >= -3.4e38f;
}

uint16_t h2df_duty_of(float torque_abs)
{
    if (!(torque_abs > 0.0f)) {
        return 0;
    }
    if (torque_abs >= H2DF_TORQUE_LIMIT) {
        return (uint16_t)H2DF_DUTY_MAX;
    }
    float d = torque_abs / H2DF_TORQUE_LIMIT * (float)H2DF_DUTY_MAX + 0.5f;
    uint16_t duty = (uint16_t)d;
    return duty > H2DF_DUTY_MAX ? (uint16_t)H2DF_DUTY_MAX : duty;
}

static void motors_zero(struct h2df *fw)
{
    for (uint8_t p = 0; p < H2DF_PORTS; p++) {
        h2df_hal_motor(p, 0, false);
    }
    fw->motors_on = false;
}

static void forget_setup(struct h2df *fw)
{
    fw->motor_mask = 0;
    fw->enc_mask = 0;
    fw->n_sensors = 0;
    fw->n_pwm = 0;
    for (uint8_t p = 0; p < H2DF_WIRE_PORTS; p++) {
        fw->motor_sign[p] = -1;
        fw->enc_sign[p] = -1;
        fw->enc_base[p] = 0;
        fw->enc_resolution[p] = 0.0f;
    }
}

void h2df_init(struct h2df *fw)
{
    memset(fw, 0, sizeof *fw);
    h2df_hal_init();
    motors_zero(fw);
    forget_setup(fw);
    fw->watchdog_ms = H2DF_WATCHDOG_DEFAULT_MS;
    fw->last_write_us = h2df_hal_micros();
}

void h2df_identity(const struct h2df *fw, uint8_t out[H2DF_IDENTITY_LEN])
{
    out[0] = H2DF_CMD_IDENTIFY;
    out[1] = 'H';
    out[2] = '2';
    out[3] = 'D';
    out[4] = 'F';
    out[5] = H2DF_FW_VERSION;
    out[6] = H2DF_PORTS;
    out[7] = H2DF_CAPS;
    out[8] = (uint8_t)(fw->watchdog_ms & 0xffu);
    out[9] = (uint8_t)(fw->watchdog_ms >> 8);
}

static void send_identity(const struct h2df *fw)
{
    uint8_t out[H2DF_IDENTITY_LEN];
    h2df_identity(fw, out);
    h2df_serial_write(out, sizeof out);
}

/* Length of the setup frame at the start of rx: 0 while incomplete, -1 when it cannot be one. */
static int setup_len(const uint8_t *b, uint16_t len)
{
    uint16_t at = 2; /* [0x01][id] */
    if (len < at + 1) return 0;
    uint8_t n_m = popcount4(b[at] & 0x0fu);
    at = (uint16_t)(at + 1 + n_m);
    if (len < at + 1) return 0;
    uint8_t n_e = popcount4(b[at] & 0x0fu);
    at = (uint16_t)(at + 1 + n_e);
    if (len < at + 1) return 0;
    if (b[at] > H2DF_MAX_SENSORS) return -1;
    at = (uint16_t)(at + 1 + b[at]);
    if (len < at + 1) return 0;
    if (b[at] > H2DF_WIRE_PORTS) return -1;
    at = (uint16_t)(at + 1 + b[at]);
    at = (uint16_t)(at + 8u * n_e);
    return len < at ? 0 : (int)at;
}

static void apply_setup(struct h2df *fw, const uint8_t *b)
{
    motors_zero(fw);
    forget_setup(fw);
    uint16_t at = 2;
    fw->motor_mask = b[at++] & 0x0fu;
    /* Direction bytes go to the used ports in ascending port order. */
    for (uint8_t p = 0; p < H2DF_WIRE_PORTS; p++) {
        if (fw->motor_mask & (1u << p)) {
            fw->motor_sign[p] = b[at++] ? 1 : -1;
        }
    }
    fw->enc_mask = b[at++] & 0x0fu;
    for (uint8_t p = 0; p < H2DF_WIRE_PORTS; p++) {
        if (fw->enc_mask & (1u << p)) {
            fw->enc_sign[p] = b[at++] ? 1 : -1;
        }
    }
    fw->n_sensors = b[at++];
    for (uint8_t i = 0; i < fw->n_sensors; i++) {
        /* Insertion sort: analog values are reported in ascending pin order. */
        uint8_t pin = b[at++];
        uint8_t j = i;
        while (j > 0 && fw->sensor_pins[j - 1] > pin) {
            fw->sensor_pins[j] = fw->sensor_pins[j - 1];
            j--;
        }
        fw->sensor_pins[j] = pin;
    }
    fw->n_pwm = b[at++];
    for (uint8_t i = 0; i < fw->n_pwm; i++) {
        fw->pwm_pins[i] = b[at++];
    }
    for (uint8_t p = 0; p < H2DF_WIRE_PORTS; p++) {
        if (!(fw->enc_mask & (1u << p))) continue;
        float offset = get_f32(b + at);
        float resolution = get_f32(b + at + 4);
        at = (uint16_t)(at + 8);
        fw->enc_resolution[p] = resolution;
        /* The count the handle has at the rest pose, truncated towards zero. */
        float count = offset * resolution / 360.0f;
        fw->enc_base[p] = finite_f32(count) && count < 2.0e9f && count > -2.0e9f
            ? (int32_t)count
            : 0;
        if (p < H2DF_PORTS) {
            h2df_hal_encoder_zero(p);
        }
    }
    /* Setting up never moves a motor: they stay zero until the first write. */
    motors_zero(fw);
}

static uint16_t write_len(const struct h2df *fw)
{
    return (uint16_t)(2u + fw->n_pwm + 4u * popcount4(fw->motor_mask));
}

static void apply_write(struct h2df *fw, const uint8_t *b)
{
    uint8_t id = b[1];
    uint16_t at = 2;
    for (uint8_t i = 0; i < fw->n_pwm; i++) {
        h2df_hal_user_pwm(fw->pwm_pins[i], b[at++]);
    }
    bool on = false;
    for (uint8_t p = 0; p < H2DF_WIRE_PORTS; p++) {
        if (!(fw->motor_mask & (1u << p))) continue;
        float t = get_f32(b + at);
        at = (uint16_t)(at + 4);
        if (p >= H2DF_PORTS) continue; /* a port this board lacks */
        if (!finite_f32(t)) t = 0.0f;
        if (t > H2DF_TORQUE_LIMIT) t = H2DF_TORQUE_LIMIT;
        if (t < -H2DF_TORQUE_LIMIT) t = -H2DF_TORQUE_LIMIT;
        /* Direction pin: counter-clockwise drive when the torque's sign agrees with the motor's
         * direction byte. */
        bool ccw = (t >= 0.0f) == (fw->motor_sign[p] > 0);
        uint16_t duty = h2df_duty_of(t >= 0.0f ? t : -t);
        h2df_hal_motor(p, duty, ccw);
        on = on || duty != 0;
    }
    fw->motors_on = on;
    fw->last_write_us = h2df_hal_micros();
    fw->writes++;
    h2df_hal_event(H2DF_EV_WRITE);

    /* The reply: encoders sampled now. */
    uint8_t out[H2DF_REPLY_MAX];
    uint16_t n = 0;
    out[n++] = id;
    for (uint8_t i = 0; i < fw->n_sensors; i++) {
        put_f32(out + n, h2df_hal_analog(fw->sensor_pins[i]));
        n = (uint16_t)(n + 4);
    }
    for (uint8_t p = 0; p < H2DF_PORTS; p++) {
        if (!(fw->enc_mask & (1u << p))) continue;
        int32_t count = fw->enc_base[p] + fw->enc_sign[p] * h2df_hal_encoder_raw(p);
        float r = fw->enc_resolution[p];
        float angle = (finite_f32(r) && r > 0.0f) ? 360.0f * (float)count / r : 0.0f;
        put_f32(out + n, angle);
        n = (uint16_t)(n + 4);
    }
    h2df_serial_write(out, n);
}

/* Services the frame at the start of rx; returns the bytes it used, 0 if it is incomplete. */
static uint16_t service_one(struct h2df *fw)
{
    const uint8_t *b = fw->rx;
    uint16_t len = fw->rx_len;
    switch (b[0]) {
    case H2DF_CMD_RESET:
        if (len < 2) return 0;
        motors_zero(fw);
        forget_setup(fw);
        h2df_hal_event(H2DF_EV_RESET);
        return 2;
    case H2DF_CMD_SETUP: {
        int n = setup_len(b, len);
        if (n == 0) return 0;
        if (n < 0) break; /* garbage: skip the byte below */
        apply_setup(fw, b);
        h2df_hal_event(H2DF_EV_SETUP);
        return (uint16_t)n;
    }
    case H2DF_CMD_WRITE: {
        uint16_t n = write_len(fw);
        if (len < n) return 0;
        apply_write(fw, b);
        return n;
    }
    case H2DF_CMD_IDENTIFY:
        h2df_hal_event(H2DF_EV_IDENTIFY);
        send_identity(fw);
        return 1;
    case H2DF_CMD_SET_WATCHDOG: {
        if (len < 3) return 0;
        uint16_t ms = (uint16_t)(b[1] | (b[2] << 8));
        if (ms >= H2DF_WATCHDOG_MIN_MS && ms <= H2DF_WATCHDOG_MAX_MS) {
            fw->watchdog_ms = ms;
        }
        h2df_hal_event(H2DF_EV_IDENTIFY);
        send_identity(fw);
        return 3;
    }
    default:
        break;
    }
    /* Not a command: skip one byte (as the stock firmware does). */
    fw->bad_bytes++;
    h2df_hal_event(H2DF_EV_BAD_BYTE);
    return 1;
}

static void watchdog(struct h2df *fw)
{
    if (!fw->motors_on) return;
    uint32_t quiet = h2df_hal_micros() - fw->last_write_us; /* wraps correctly */
    if (quiet >= (uint32_t)fw->watchdog_ms * 1000u) {
        motors_zero(fw);
        fw->watchdog_trips++;
        h2df_hal_event(H2DF_EV_WATCHDOG_TRIP);
    }
}

void h2df_poll(struct h2df *fw)
{
    /* The watchdog first: a write that is waiting now cannot excuse a silence already over. */
    watchdog(fw);
    bool got = false;
    while (fw->rx_len < H2DF_RX_SIZE && h2df_serial_available() > 0) {
        int c = h2df_serial_read();
        if (c < 0) break;
        fw->rx[fw->rx_len++] = (uint8_t)c;
        got = true;
    }
    if (got) {
        fw->rx_last_us = h2df_hal_micros();
    } else if (fw->rx_len > 0 && h2df_hal_micros() - fw->rx_last_us >= H2DF_STALE_FRAME_US) {
        /* What is left is an incomplete frame nobody is finishing. */
        fw->rx_len = 0;
        fw->stale_frames++;
        h2df_hal_event(H2DF_EV_STALE_FRAME);
    }
    while (fw->rx_len > 0) {
        uint16_t used = service_one(fw);
        if (used == 0) break;
        memmove(fw->rx, fw->rx + used, (size_t)(fw->rx_len - used));
        fw->rx_len = (uint16_t)(fw->rx_len - used);
    }
    watchdog(fw);
}
