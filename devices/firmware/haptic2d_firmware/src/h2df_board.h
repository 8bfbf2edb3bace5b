/* haptic2d firmware: which board the core is built for (ports, PWM resolution).
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * Selected by -DH2DF_BOARD_M0 or -DH2DF_BOARD_M3, else from the Arduino core's chip macros
 * (SAMD51 or SAM3X8E → M3, SAMD21 → M0). The native build defaults to M3. */
#ifndef H2DF_BOARD_H
#define H2DF_BOARD_H

#if !defined(H2DF_BOARD_M0) && !defined(H2DF_BOARD_M3)
#if defined(__SAMD51__) || defined(__SAM3X8E__)
#define H2DF_BOARD_M3 1
#elif defined(__SAMD21__) || defined(__SAMD21G18A__) || defined(__SAMD21E18A__) || \
    defined(__SAMD21J18A__)
#define H2DF_BOARD_M0 1
#elif defined(H2DF_NATIVE)
#define H2DF_BOARD_M3 1
#else
#error "haptic2d firmware: unknown board; build for a SAMD21 (M0) or a SAMD51/SAM3X8E (M3), or define H2DF_BOARD_M0 / H2DF_BOARD_M3"
#endif
#endif

#if defined(H2DF_BOARD_M0) && defined(H2DF_BOARD_M3)
#error "haptic2d firmware: define only one of H2DF_BOARD_M0 and H2DF_BOARD_M3"
#endif

#if defined(H2DF_BOARD_M3)
#define H2DF_BOARD_NAME "M3"
#define H2DF_PORTS 4u      /* motor/encoder ports on the board */
#define H2DF_PWM_BITS 12u  /* PWM resolution */
#else
#define H2DF_BOARD_NAME "M0"
#define H2DF_PORTS 2u
#define H2DF_PWM_BITS 10u
#endif

/* Largest PWM duty (full on). */
#define H2DF_DUTY_MAX ((1u << H2DF_PWM_BITS) - 1u)

#endif
