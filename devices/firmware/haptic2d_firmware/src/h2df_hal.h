/* haptic2d firmware: what the core needs from the hardware. board.c implements it with Arduino
 * calls; the serial functions are implemented by the sketch (haptic2d_firmware.ino), or by the
 * native stub on Linux.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * Ports are 0-based (port 1 on the wire is 0 here) and below H2DF_PORTS. */
#ifndef H2DF_HAL_H
#define H2DF_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Serial port (USB CDC). */
int h2df_serial_available(void);                  /* bytes waiting */
int h2df_serial_read(void);                       /* next byte, or -1 */
void h2df_serial_write(const uint8_t *bytes, size_t n);

/* Board. */
void h2df_hal_init(void);       /* pins, PWM, encoders; every motor output zero */
uint32_t h2df_hal_micros(void); /* free-running µs clock (wraps) */
/* Motor output of `port`: `duty` 0..H2DF_DUTY_MAX, direction pin high when `ccw`. */
void h2df_hal_motor(uint8_t port, uint16_t duty, bool ccw);
void h2df_hal_encoder_zero(uint8_t port);    /* raw quadrature count of `port` to 0 */
int32_t h2df_hal_encoder_raw(uint8_t port);  /* raw count since the last zero */
float h2df_hal_analog(uint8_t wire_pin);     /* ADC value of analog pin 54-65 (A0-A11) */
void h2df_hal_user_pwm(uint8_t pin, uint8_t duty); /* a setup's extra PWM pin (never a motor pin) */
void h2df_hal_event(uint8_t event);          /* enum h2df_event; may do nothing */

#ifdef __cplusplus
}
#endif

#endif
