/* haptic2d firmware: the board's pin map (motor PWM and direction, encoder A/B, analog inputs).
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * The pin map of a Haply M0/M3 board is NOT among the protocol facts this firmware was written
 * from, and a wrong pin map drives the wrong pins. So a board build stops here until you have
 * copied the pins from your board's schematic into the H2DF_PINS_* lists below and defined
 * H2DF_PINS_VERIFIED (edit this file, or pass -DH2DF_PINS_VERIFIED, see docs/FIRMWARE.md).
 * The native build (H2DF_NATIVE) uses its own made-up numbering: the stub reads it back from here
 * to log what the motors do. */
#ifndef H2DF_BOARD_PINS_H
#define H2DF_BOARD_PINS_H

#include "h2df_board.h"

#if defined(H2DF_NATIVE)

/* Native stub numbering (not a real board): port k (0-based) has PWM pin 2+k, direction pin 6+k,
 * encoder A pin 10+2k, B pin 11+2k; the analog pins keep their wire numbers 54-65. */
#define H2DF_PINS_PWM {2, 3, 4, 5}
#define H2DF_PINS_DIR {6, 7, 8, 9}
#define H2DF_PINS_ENC_A {10, 12, 14, 16}
#define H2DF_PINS_ENC_B {11, 13, 15, 17}
#define H2DF_PINS_ANALOG {54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 65}

#else

/* Uncomment once the lists below are your board's pins: */
/* #define H2DF_PINS_VERIFIED 1 */

#if !defined(H2DF_PINS_VERIFIED)
#error "haptic2d firmware: fill in board_pins.h from your board's schematic, then define H2DF_PINS_VERIFIED (docs/FIRMWARE.md)"
#endif

/* *verify*: replace every 0xff by the Arduino pin number of your board (one entry per port,
 * port 1 first; an M0 uses the first 2). 0xff means "not connected" and is never driven. */
#define H2DF_PINS_PWM {0xff, 0xff, 0xff, 0xff}
#define H2DF_PINS_DIR {0xff, 0xff, 0xff, 0xff}
#define H2DF_PINS_ENC_A {0xff, 0xff, 0xff, 0xff}
#define H2DF_PINS_ENC_B {0xff, 0xff, 0xff, 0xff}
/* Arduino pin numbers of A0..A11 (wire pins 54..65); 0xff where the board has no such input. */
#define H2DF_PINS_ANALOG {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff}

#endif

/* "Not connected". */
#define H2DF_NO_PIN 0xffu

#endif
