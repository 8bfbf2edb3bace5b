/* haptic2d firmware: the hardware layer (h2df_hal.h) on the Arduino API. The same file builds
 * for a SAMD21/SAMD51 board with arduino-cli and natively against the stub in ../../native.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * Motors: one PWM pin (duty 0..H2DF_DUTY_MAX, analogWriteResolution(H2DF_PWM_BITS)) and one
 * direction pin per port. Encoders: A/B quadrature decoded in pin-change interrupts, 4 counts per
 * cycle. */
#include <Arduino.h>

#include "board_pins.h"
#include "h2df.h"
#include "h2df_hal.h"

static const uint8_t pwm_pin[4] = H2DF_PINS_PWM;
static const uint8_t dir_pin[4] = H2DF_PINS_DIR;
static const uint8_t enc_a[4] = H2DF_PINS_ENC_A;
static const uint8_t enc_b[4] = H2DF_PINS_ENC_B;
static const uint8_t analog_pin[12] = H2DF_PINS_ANALOG;

static volatile int32_t enc_count[4];
static volatile uint8_t enc_state[4];
static uint8_t dir_now[4];

/* Quadrature step for (previous AB << 2 | new AB): +1, -1, or 0 (no change or a skipped state). */
static const int8_t QUAD[16] = {0, 1, -1, 0, -1, 0, 0, 1, 1, 0, 0, -1, 0, -1, 1, 0};

static void enc_update(uint8_t p)
{
    uint8_t ab = (uint8_t)((digitalRead(enc_a[p]) ? 2u : 0u) | (digitalRead(enc_b[p]) ? 1u : 0u));
    enc_count[p] += QUAD[(enc_state[p] << 2) | ab];
    enc_state[p] = ab;
}

static void enc_isr0(void) { enc_update(0); }
static void enc_isr1(void) { enc_update(1); }
static void enc_isr2(void) { enc_update(2); }
static void enc_isr3(void) { enc_update(3); }
static void (*const enc_isr[4])(void) = {enc_isr0, enc_isr1, enc_isr2, enc_isr3};

static bool is_motor_pin(uint8_t pin)
{
    for (uint8_t p = 0; p < H2DF_PORTS; p++) {
        if (pin == pwm_pin[p] || pin == dir_pin[p] || pin == enc_a[p] || pin == enc_b[p]) {
            return true;
        }
    }
    return false;
}

void h2df_hal_init(void)
{
    analogWriteResolution(H2DF_PWM_BITS);
    for (uint8_t p = 0; p < H2DF_PORTS; p++) {
        if (pwm_pin[p] != H2DF_NO_PIN) {
            pinMode(pwm_pin[p], OUTPUT);
            analogWrite(pwm_pin[p], 0);
        }
        if (dir_pin[p] != H2DF_NO_PIN) {
            pinMode(dir_pin[p], OUTPUT);
            digitalWrite(dir_pin[p], LOW);
        }
        dir_now[p] = LOW;
        if (enc_a[p] != H2DF_NO_PIN && enc_b[p] != H2DF_NO_PIN) {
            pinMode(enc_a[p], INPUT_PULLUP);
            pinMode(enc_b[p], INPUT_PULLUP);
            enc_state[p] = (uint8_t)((digitalRead(enc_a[p]) ? 2u : 0u) |
                                     (digitalRead(enc_b[p]) ? 1u : 0u));
            enc_count[p] = 0;
            attachInterrupt(digitalPinToInterrupt(enc_a[p]), enc_isr[p], CHANGE);
            attachInterrupt(digitalPinToInterrupt(enc_b[p]), enc_isr[p], CHANGE);
        }
    }
}

uint32_t h2df_hal_micros(void)
{
    return (uint32_t)micros();
}

void h2df_hal_motor(uint8_t port, uint16_t duty, bool ccw)
{
    if (port >= H2DF_PORTS || pwm_pin[port] == H2DF_NO_PIN) return;
    uint8_t level = ccw ? HIGH : LOW;
    if (level != dir_now[port] && dir_pin[port] != H2DF_NO_PIN) {
        /* Never drive the old direction with the new duty: off, turn, on. */
        analogWrite(pwm_pin[port], 0);
        digitalWrite(dir_pin[port], level);
        dir_now[port] = level;
    }
    analogWrite(pwm_pin[port], duty);
}

void h2df_hal_encoder_zero(uint8_t port)
{
    if (port >= H2DF_PORTS) return;
    noInterrupts();
    enc_count[port] = 0;
    interrupts();
}

int32_t h2df_hal_encoder_raw(uint8_t port)
{
    if (port >= H2DF_PORTS) return 0;
    noInterrupts();
    int32_t c = enc_count[port];
    interrupts();
    return c;
}

float h2df_hal_analog(uint8_t wire_pin)
{
    if (wire_pin < H2DF_ANALOG_PIN_MIN || wire_pin > H2DF_ANALOG_PIN_MAX) return 0.0f;
    uint8_t pin = analog_pin[wire_pin - H2DF_ANALOG_PIN_MIN];
    if (pin == H2DF_NO_PIN) return 0.0f;
    return (float)analogRead(pin);
}

void h2df_hal_user_pwm(uint8_t pin, uint8_t duty)
{
    /* A host may name any pin; never one that drives or reads a motor port. The duty is 8-bit on
     * the wire and scaled to the PWM resolution. */
    if (pin == H2DF_NO_PIN || is_motor_pin(pin)) return;
    analogWrite(pin, (uint32_t)duty * H2DF_DUTY_MAX / 255u);
}

#if !defined(H2DF_NATIVE)
void h2df_hal_event(uint8_t event)
{
    (void)event;
}
#endif
