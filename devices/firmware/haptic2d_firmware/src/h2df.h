/* haptic2d firmware for Haply M0/M3 boards: the board-independent core.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 * Written from scratch for haptic2d from the protocol facts in the project's device notes
 * (DEVICES §1); docs/FIRMWARE.md describes the protocol, the additions and how to build it.
 *
 * Wire protocol (USB serial, no framing; f32 little-endian; angles in degrees, torques in N·m):
 *
 *   host → board  reset     [0x00][id]                                               no reply
 *                 setup     [0x01][id][motor_mask][motor_dir × n_m][enc_mask][enc_dir × n_e]
 *                           [n_sensors][pin × n_s][n_pwm][pin × n_p]
 *                           [offset_deg f32, resolution f32] × n_e                  no reply
 *                 write     [0x02][id][pwm u8 × n_p][torque f32 × n_m]           → reply
 *                 identify  [0x03]                                               → identity
 *                 watchdog  [0x04][watchdog_ms u16 LE]                           → identity
 *   board → host  reply     [id][analog f32 × n_s][angle_deg f32 × n_e]
 *                 identity  [0x03]['H','2','D','F'][fw_version][ports][caps][watchdog_ms u16 LE]
 *
 * 0x00-0x02 are the stock firmware's protocol; 0x03 and 0x04 are haptic2d's (a stock board skips
 * them as unknown command bytes and sends nothing back).
 *
 * The core owns no hardware: it calls the functions of h2df_hal.h (board.c on a board, the native
 * stub on Linux). One call of h2df_poll() services everything that arrived and the watchdog; the
 * sketch's loop() calls it as often as it can. */
#ifndef H2DF_H
#define H2DF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "h2df_board.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Command bytes. */
#define H2DF_CMD_RESET 0x00u
#define H2DF_CMD_SETUP 0x01u
#define H2DF_CMD_WRITE 0x02u
#define H2DF_CMD_IDENTIFY 0x03u
#define H2DF_CMD_SET_WATCHDOG 0x04u

/* The torque clamp |τ| ≤ 0.123 N·m, applied before the PWM conversion (the stock firmware's). */
#define H2DF_TORQUE_LIMIT 0.123f
/* Firmware version reported by identify. */
#define H2DF_FW_VERSION 1u
/* Watchdog: default and valid range (ms). */
#define H2DF_WATCHDOG_DEFAULT_MS 20u
#define H2DF_WATCHDOG_MIN_MS 1u
#define H2DF_WATCHDOG_MAX_MS 1000u
/* Capability bits of the identity frame. */
#define H2DF_CAP_WATCHDOG 0x01u        /* motors zero when no write arrives in time */
#define H2DF_CAP_RESET_ZEROES 0x02u    /* reset zeroes the motor outputs */
#define H2DF_CAP_TORQUE_CLAMP 0x04u    /* the torque clamp runs on the board */
#define H2DF_CAPS (H2DF_CAP_WATCHDOG | H2DF_CAP_RESET_ZEROES | H2DF_CAP_TORQUE_CLAMP)
/* Length of the identity frame (bytes). */
#define H2DF_IDENTITY_LEN 10u

/* Protocol sizes: ports on the wire (masks have 4 bits), analog pins 54-65 (A0-A11). */
#define H2DF_WIRE_PORTS 4u
#define H2DF_MAX_SENSORS 12u
#define H2DF_ANALOG_PIN_MIN 54u
#define H2DF_ANALOG_PIN_MAX 65u
/* Largest reply: 1 + 4·(12 + 4). */
#define H2DF_REPLY_MAX 65u
/* Receive buffer: larger than the largest frame (a setup is at most 62 bytes). */
#define H2DF_RX_SIZE 128u
/* An incomplete frame that has received no byte for this long (µs) is dropped: a host that died
 * in the middle of a frame must not have the next host's first bytes read as its torques. A host
 * writes a frame in one go (a few USB packets, well under a millisecond). */
#define H2DF_STALE_FRAME_US 10000u

/* Events the core reports to the board layer (h2df_hal_event): a board may ignore them, the native
 * stub logs them. */
enum h2df_event {
    H2DF_EV_RESET = 0,
    H2DF_EV_SETUP = 1,
    H2DF_EV_WRITE = 2,
    H2DF_EV_IDENTIFY = 3,
    H2DF_EV_WATCHDOG_TRIP = 4,
    H2DF_EV_BAD_BYTE = 5,
    H2DF_EV_STALE_FRAME = 6,
};

/* The firmware's whole state. */
struct h2df {
    /* Bytes received and not yet serviced. */
    uint8_t rx[H2DF_RX_SIZE];
    uint16_t rx_len;
    uint32_t rx_last_us; /* h2df_hal_micros() when the last byte arrived */

    /* The current setup, as sent (masks keep all 4 wire ports: frame lengths depend on them). */
    uint8_t motor_mask;
    uint8_t enc_mask;
    int8_t motor_sign[H2DF_WIRE_PORTS]; /* +1 counter-clockwise, -1 clockwise */
    int8_t enc_sign[H2DF_WIRE_PORTS];
    int32_t enc_base[H2DF_WIRE_PORTS];  /* trunc(offset·resolution/360) at the last setup */
    float enc_resolution[H2DF_WIRE_PORTS];
    uint8_t n_sensors;
    uint8_t sensor_pins[H2DF_MAX_SENSORS]; /* ascending */
    uint8_t n_pwm;
    uint8_t pwm_pins[H2DF_WIRE_PORTS];

    /* Motor outputs. */
    bool motors_on;          /* some output is nonzero */
    uint32_t last_write_us;  /* h2df_hal_micros() of the last write */
    uint16_t watchdog_ms;

    /* Counters (for a debugger; never sent). */
    uint32_t writes;
    uint32_t watchdog_trips;
    uint32_t bad_bytes;
    uint32_t stale_frames;
};

/* Puts the board in its power-up state: hardware initialised, every motor output zero, nothing set
 * up, the default watchdog. */
void h2df_init(struct h2df *fw);

/* Reads what the serial port holds, services every complete frame, then the watchdog. */
void h2df_poll(struct h2df *fw);

/* The identity frame (H2DF_IDENTITY_LEN bytes) into out. */
void h2df_identity(const struct h2df *fw, uint8_t out[H2DF_IDENTITY_LEN]);

/* PWM duty (0..H2DF_DUTY_MAX) for a torque magnitude after the clamp (N·m): full duty at the
 * clamp, linear below it, rounded to the nearest step. */
uint16_t h2df_duty_of(float torque_abs);

#ifdef __cplusplus
}
#endif

#endif
